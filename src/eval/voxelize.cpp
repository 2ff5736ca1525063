#include "voxpress/eval/voxelize.h"


#include <Eigen/LU>
#include <cmath>

#include "row_rays.h"
#include "voxpress/core/error.h"
#include "voxpress/core/memory_budget.h"
#include "voxpress/eval/checks.h"
#include "core/parallel.h"

namespace voxpress {

Placement place_on_lattice(const Vec3& lo, const Vec3& hi, const Mat3& rotation, int64_t res, const Vec3& spacing,
                           int64_t margin, uint64_t max_bytes, const std::string& source) {
  if (res < 8) throw UsageError("--res must be at least 8");
  if (res > (int64_t(1) << 20)) throw UsageError("--res is absurdly large");
  if (margin < 0 || margin > res / 4) throw UsageError("--margin must be between 0 and res/4");
  for (int a = 0; a < 3; ++a)
    if (!(spacing[a] > 0) || !std::isfinite(spacing[a])) throw UsageError("--spacing values must be finite and > 0");
  const Vec3 extent = hi - lo;
  double cells = 0;
  for (int a = 0; a < 3; ++a) cells = std::max(cells, extent[a] / spacing[a]);
  if (!(cells > 0) || !std::isfinite(cells)) throw UsageError("the model has no extent");
  Placement p;
  p.scale = double(res - 1 - 2 * margin) / cells;
  for (int a = 0; a < 3; ++a) {
    const double span = p.scale * extent[a] / spacing[a];
    p.lattice.dims[size_t(a)] = std::max<int64_t>(int64_t(std::ceil(span - 1e-9)) + 1 + 2 * margin, 2);
  }
  p.lattice.spacing = spacing;
  p.lattice.validate();
  // The mask, its scalar copy and the written payload (memory_budget.h).
  if (max_bytes && p.lattice.size() > max_bytes / kVolumeOutBytesPerSample)
    throw LimitError(source, "a " + std::to_string(p.lattice.dims[0]) + "x" + std::to_string(p.lattice.dims[1]) + "x" +
                             std::to_string(p.lattice.dims[2]) + " volume (" + std::to_string(kVolumeOutBytesPerSample) +
                             " bytes a sample) exceeds the memory limit");
  p.linear = p.scale * rotation;
  const Vec3 centre = 0.5 * Vec3(double(p.lattice.dims[0] - 1), double(p.lattice.dims[1] - 1),
                                 double(p.lattice.dims[2] - 1)).cwiseProduct(spacing);
  p.translation = centre - p.scale * 0.5 * (lo + hi);
  return p;
}

BinaryVolume voxelize_on(const Mesh& mesh, const Lattice& L, Progress* progress) {
  BinaryVolume out;
  out.lattice = L;
  out.inside.assign(L.size(), 0);
  const Mat3 inv = L.index_to_physical_matrix().inverse();
  std::vector<Vec3> V(mesh.positions.size());
  for (size_t v = 0; v < V.size(); ++v) V[v] = inv * (mesh.positions[v] - L.origin);
  const std::array<int64_t, 3> lo{0, 0, 0}, hi{L.dims[0] - 1, L.dims[1] - 1, L.dims[2] - 1};
  const detail::RowRays rays(std::move(V), mesh.triangles, lo, hi, L.flips_orientation());
  ProgressCounter counter(progress, "voxelizing", uint64_t(L.dims[2]));
  detail::parallel_for(int64_t(0), L.dims[2], [&](int64_t k) {
    std::vector<int> winding;
    std::vector<uint8_t> odd;
    std::vector<int64_t> on_surface;
    for (int64_t j = 0; j < L.dims[1]; ++j) {
      rays.classify(j, k, winding, odd, on_surface);
      uint8_t* row = out.inside.data() + L.linear(0, j, k);
      for (int64_t i = 0; i < L.dims[0]; ++i) row[i] = winding[size_t(i)] != 0 ? 1 : 0;
      for (int64_t i : on_surface) row[i] = 1;
    }
    counter.add(1);
  });
  return out;
}

void require_solid(const Mesh& model, const std::string& source) {
  model.validate(source);
  if (model.triangles.empty()) throw InputError(source, "the mesh has no triangles");
  MeshCheckOptions mo;
  mo.self_intersections = false;
  const MeshCheck c = check_mesh(model, mo);
  if (c.boundary_edges)
    throw InputError(source, "the mesh is not closed: " + std::to_string(c.boundary_edges) +
                                 " boundary edges (a solid needs a watertight surface)");
  if (c.nonmanifold_edges) throw InputError(source, std::to_string(c.nonmanifold_edges) + " non-manifold edges");
  if (c.misoriented_edges)
    throw InputError(source, "inconsistently oriented faces (" + std::to_string(c.misoriented_edges) + " edges)");
}

Voxelized voxelize(const Mesh& model, const VoxelizeOptions& o, const std::string& source) {
  require_solid(model, source);
  // Rotated bounding box from the vertices (exact for a polyhedron).
  Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
  for (const Vec3& p : model.positions) {
    const Vec3 q = o.rotation * p;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  Voxelized v;
  v.placement = place_on_lattice(lo, hi, o.rotation, o.res, o.spacing, o.margin, o.max_bytes, source);
  Mesh physical;
  physical.positions.reserve(model.positions.size());
  for (const Vec3& p : model.positions) physical.positions.push_back(v.placement.translation + v.placement.linear * p);
  physical.triangles = model.triangles;
  v.volume = voxelize_on(physical, v.placement.lattice, o.progress);
  v.volume.source = source;
  return v;
}

bool mesh_contains(const Mesh& mesh, const Vec3& point) {
  // Shift the point to the origin and classify the single sample (0, 0, 0).
  std::vector<Vec3> V(mesh.positions.size());
  for (size_t v = 0; v < V.size(); ++v) V[v] = mesh.positions[v] - point;
  const detail::RowRays rays(std::move(V), mesh.triangles, {0, 0, 0}, {0, 0, 0}, false);
  std::vector<int> winding;
  std::vector<uint8_t> odd;
  std::vector<int64_t> on_surface;
  rays.classify(0, 0, winding, odd, on_surface);
  return winding[0] != 0 || !on_surface.empty();
}

}  // namespace voxpress
