// Mesh-level constrained smoothing (Bade, Konrad and Preim) and the
// unconstrained Laplacian / Taubin baselines. Theory of operation:
// include/voxpress/smooth/mesh_smoothing.h.
#include "voxpress/smooth/mesh_smoothing.h"


#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/timing.h"
#include "smooth/surface_graph.h"
#include "voxpress/core/error.h"
#include "core/parallel.h"

namespace voxpress {

using detail::seconds_since;

namespace {

const char* axis_name(int a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

std::string where(const Vec3& p) { return fmt("(%.9g, %.9g, %.9g)", p.x(), p.y(), p.z()); }

}  // namespace

Vec3 LatticeMesh::midpoint(size_t v) const {
  Vec3 m = Vec3(double(lower[v][0]), double(lower[v][1]), double(lower[v][2]));
  m[axis[v]] += 0.5;
  return m;
}

// ------------------------------------------------------------ Section 3
LatticeMesh recover_lattice(Mesh mesh, const std::string& source, const RecoverOptions& options) {
  const double tol = options.tolerance;
  if (!(tol > 0 && tol < 0.25)) throw UsageError("lattice recovery tolerance must be in (0, 0.25)");
  LatticeMesh out;
  out.welded = weld_identical_vertices(mesh);
  mesh.validate(source);
  if (mesh.triangles.empty()) throw InputError(source, "not a marching-cubes mesh: it has no triangles");
  const size_t n = mesh.vertex_count();

  // 3.2 Cell size: every triangle edge of a marching-cubes mesh extends 0,
  // h/2 or h along each axis (its ends lie on edges of one cell). h/2 is
  // the smallest non-zero extent; h is then averaged over both clusters so
  // that float32 rounding (STL) does not bias it.
  Vec3 magnitude = Vec3::Zero();
  for (const Vec3& p : mesh.positions) magnitude = magnitude.cwiseMax(p.cwiseAbs());
  Vec3 h;
  for (int a = 0; a < 3; ++a) {
    const double noise = 4e-7 * magnitude[a];  // a few float32 ulps of the largest coordinate
    double half = HUGE_VAL;
    for (const Triangle& t : mesh.triangles)
      for (int e = 0; e < 3; ++e) {
        const double d = std::abs(mesh.positions[t[size_t(e)]][a] - mesh.positions[t[size_t((e + 1) % 3)]][a]);
        if (d > noise) half = std::min(half, d);
      }
    if (half == HUGE_VAL)
      throw InputError(source, std::string("not a marching-cubes mesh: no triangle edge extends along ") + axis_name(a) +
                                   ", so there is no cell size (flat mesh?)");
    double sum = 0;
    size_t count = 0;
    for (const Triangle& t : mesh.triangles)
      for (int e = 0; e < 3; ++e) {
        const uint32_t i = t[size_t(e)], j = t[size_t((e + 1) % 3)];
        const double d = std::abs(mesh.positions[i][a] - mesh.positions[j][a]);
        if (std::abs(d - half) <= tol * 2 * half) {
          sum += 2 * d;
          ++count;
        } else if (std::abs(d - 2 * half) <= tol * 2 * half) {
          sum += d;
          ++count;
        } else if (d > noise + tol * 2 * half) {
          throw InputError(source, std::string("not an axis-aligned marching-cubes mesh: triangle edge extents along ") +
                                       axis_name(a) + " are not 0, h/2 and h for one cell size h (the shortest is " +
                                       fmt("%.6g", half) + ", edge " + std::to_string(i) + "-" + std::to_string(j) +
                                       " extends " + fmt("%.6g", d) + "): rotated, remeshed, decimated or smoothed?");
        }
      }
    h[a] = sum / double(count);
  }

  // 3.3 Cell centre, here the sample phase: the lowest vertex (x first) lies
  // on an x-edge, half a cell before the lowest inside sample along x, and on
  // samples along y and z.
  size_t low = 0;
  for (size_t v = 1; v < n; ++v) {
    const Vec3& p = mesh.positions[v];
    const Vec3& m = mesh.positions[low];
    if (std::tie(p.x(), p.y(), p.z()) < std::tie(m.x(), m.y(), m.z())) low = v;
  }
  const Vec3 phase = mesh.positions[low] + Vec3(0.5 * h.x(), 0, 0);

  // 3.4 Cell edge: exactly one coordinate of a vertex is half-way between
  // samples (the edge's axis), the other two are on samples.
  out.lower.resize(n);
  out.axis.resize(n);
  std::array<int64_t, 3> lo{INT64_MAX, INT64_MAX, INT64_MAX}, hi{INT64_MIN, INT64_MIN, INT64_MIN};
  for (size_t v = 0; v < n; ++v) {
    const Vec3 u = (mesh.positions[v] - phase).cwiseQuotient(h);
    int axis = -1, mids = 0;
    for (int a = 0; a < 3; ++a) {
      const double r = std::abs(u[a] - std::round(u[a]));  // 0 on a sample, 1/2 half-way
      const double off = std::min(r, 0.5 - r);
      if (off > tol)
        throw InputError(source, "not an axis-aligned marching-cubes mesh: vertex " + std::to_string(v) + " at " +
                                     where(mesh.positions[v]) + " is " + fmt("%.3g", off) + " cells off the lattice along " +
                                     axis_name(a) + " (rotated, remeshed or smoothed?)");
      out.misfit = std::max(out.misfit, off);
      if (r > 0.25) {
        axis = a;
        ++mids;
      }
    }
    if (mids != 1)
      throw InputError(source, "not a marching-cubes mesh: vertex " + std::to_string(v) + " at " +
                                   where(mesh.positions[v]) + " is half-way between samples along " + std::to_string(mids) +
                                   " axes, not at a lattice edge midpoint");
    std::array<int64_t, 3> idx{};
    for (int a = 0; a < 3; ++a) idx[size_t(a)] = int64_t(std::llround(a == axis ? u[a] - 0.5 : u[a]));
    out.lower[v] = idx;
    out.axis[v] = uint8_t(axis);
    for (int a = 0; a < 3; ++a) {
      lo[size_t(a)] = std::min(lo[size_t(a)], idx[size_t(a)]);
      hi[size_t(a)] = std::max(hi[size_t(a)], idx[size_t(a)] + (a == axis ? 1 : 0));
    }
  }
  // One vertex per edge.
  std::vector<uint32_t> order(n);
  for (size_t v = 0; v < n; ++v) order[v] = uint32_t(v);
  auto key = [&](uint32_t v) { return std::tie(out.lower[v], out.axis[v]); };
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
  for (size_t k = 1; k < n; ++k)
    if (key(order[k]) == key(order[k - 1]))
      throw InputError(source, "not a marching-cubes mesh: vertices " + std::to_string(order[k - 1]) + " and " +
                                   std::to_string(order[k]) + " lie on the same lattice edge");

  Lattice& l = out.lattice;
  l.spacing = h;
  for (int a = 0; a < 3; ++a) {
    l.origin[a] = phase[a] + double(lo[size_t(a)]) * h[a];
    l.dims[size_t(a)] = hi[size_t(a)] - lo[size_t(a)] + 1;
  }
  for (size_t v = 0; v < n; ++v) {
    for (int a = 0; a < 3; ++a) out.lower[v][size_t(a)] -= lo[size_t(a)];
    mesh.positions[v] = l.to_physical(out.midpoint(v));  // snap away the file's rounding
  }
  out.mesh = std::move(mesh);
  return out;
}

LatticeMesh lattice_mesh(const StickSurface& surface) {
  LatticeMesh out;
  out.mesh = to_mesh(surface);
  // The stick surface's index space is padded by one sample on each side
  // (lower indices may be -1): shift the lattice so they start at 0.
  out.lattice = surface.lattice;
  out.lattice.origin = surface.lattice.to_physical(Vec3(-1, -1, -1));
  for (int a = 0; a < 3; ++a) out.lattice.dims[size_t(a)] = surface.padded[size_t(a)];
  const size_t n = surface.stick_count();
  out.lower.resize(n);
  out.axis.resize(n);
  for (size_t s = 0; s < n; ++s) {
    std::array<int64_t, 3> idx = surface.lower_index(s);
    for (auto& c : idx) ++c;
    out.lower[s] = idx;
    out.axis[s] = uint8_t(surface.axis(s));
  }
  return out;
}

const char* constraint_name(MeshConstraint c) {
  switch (c) {
    case MeshConstraint::cell_size: return "cell-size";
    case MeshConstraint::cell_edge: return "cell-edge";
    case MeshConstraint::diamond: return "diamond";
  }
  return "?";
}

MeshConstraint parse_constraint(const std::string& name) {
  if (name == "cell-size") return MeshConstraint::cell_size;
  if (name == "cell-edge") return MeshConstraint::cell_edge;
  if (name == "diamond") return MeshConstraint::diamond;
  throw UsageError("unknown constraint '" + name + "' (expected cell-size, cell-edge or diamond)");
}

// ------------------------------------------------------------ Section 4
SmoothStats constrained_smooth(LatticeMesh& lm, const ConstrainedOptions& o) {
  if (!(o.threshold > 0)) throw UsageError("the stopping threshold must be > 0");
  if (o.max_iterations < 0) throw UsageError("the iteration cap must be >= 0");
  if (!(o.margin > 0 && o.margin < 0.5)) throw UsageError("the margin must be in (0, 0.5)");
  const auto t0 = std::chrono::steady_clock::now();
  Mesh& mesh = lm.mesh;
  const size_t n = mesh.vertex_count();
  if (lm.lower.size() != n || lm.axis.size() != n) throw std::logic_error("constrained_smooth: lattice data size");
  std::vector<uint32_t> off, adj;
  detail::vertex_adjacency(n, mesh.triangles, off, adj);

  // Index space: each vertex's region is centred on its edge midpoint c.
  std::vector<Vec3> x(n), c(n);
  for (size_t v = 0; v < n; ++v) {
    c[v] = lm.midpoint(v);
    x[v] = lm.lattice.to_index(mesh.positions[v]);
  }
  const double edge_half = 0.5 - o.margin;          // cell-edge: |d| along the edge
  const double diamond_radius = 0.5 - o.margin;     // diamond: L1 radius in cells
  auto clip = [&](size_t v, Vec3 d) -> Vec3 {
    switch (o.constraint) {
      case MeshConstraint::cell_size:  // 4.1: the box of +-1/2 cell
        return d.cwiseMax(Vec3::Constant(-0.5)).cwiseMin(Vec3::Constant(0.5));
      case MeshConstraint::cell_edge: {  // 4.3: along the edge only
        Vec3 e = Vec3::Zero();
        const int a = lm.axis[v];
        e[a] = std::clamp(d[a], -edge_half, edge_half);
        return e;
      }
      case MeshConstraint::diamond: {  // 4.4: scale back onto the octahedron along the ray
        const double l1 = d.cwiseAbs().sum();
        return l1 > diamond_radius ? Vec3(d * (diamond_radius / l1)) : d;
      }
    }
    return d;
  };

  SmoothStats st;
  ProgressCounter progress(o.progress, "constrained smoothing", uint64_t(o.max_iterations));
  const detail::Relaxation r = detail::relax(
      x, off, adj, [&](size_t v, const Vec3& mean) { return Vec3(c[v] + clip(v, mean - c[v])); }, o.threshold,
      o.max_iterations, progress);
  st.iterations = r.iterations;
  st.last_max_change = r.last_max_change;
  st.converged = r.converged;
  for (size_t v = 0; v < n; ++v) mesh.positions[v] = lm.lattice.to_physical(x[v]);
  mesh.normals.clear();  // stale once the vertices moved
  st.seconds = seconds_since(t0);
  return st;
}

// ------------------------------------------------------------ baselines
FairOptions fair_defaults(FairOptions::Kind kind) {
  FairOptions o;
  o.kind = kind;
  if (kind == FairOptions::Kind::laplacian) {
    o.lambda = 0.5;
    o.iterations = 20;
  }
  return o;
}

SmoothStats fair(Mesh& mesh, const FairOptions& o) {
  if (o.iterations < 0) throw UsageError("the iteration count must be >= 0");
  if (!std::isfinite(o.lambda) || !std::isfinite(o.mu)) throw UsageError("lambda and mu must be finite");
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = mesh.vertex_count();
  std::vector<uint32_t> off, adj;
  detail::vertex_adjacency(n, mesh.triangles, off, adj);
  std::vector<Vec3> next(n);
  std::vector<double> change(n, 0.0);
  // One simultaneous umbrella step x += f (mean(neighbours) - x).
  auto step = [&](double f) {
    detail::parallel_ranges(n, 4096, [&](detail::IndexRange r) {
      for (size_t v = r.begin(); v != r.end(); ++v) {
        const uint32_t b = off[v], e = off[v + 1];
        if (b == e) {
          next[v] = mesh.positions[v];
          continue;
        }
        Vec3 s = Vec3::Zero();
        for (uint32_t k = b; k < e; ++k) s += mesh.positions[adj[k]];
        const Vec3 d = f * (s / double(e - b) - mesh.positions[v]);
        next[v] = mesh.positions[v] + d;
        change[v] = d.norm();
      }
    });
    mesh.positions.swap(next);
  };
  SmoothStats st;
  ProgressCounter progress(o.progress, o.kind == FairOptions::Kind::taubin ? "taubin" : "laplacian",
                           uint64_t(o.iterations));
  for (int it = 0; it < o.iterations; ++it) {
    step(o.lambda);
    if (o.kind == FairOptions::Kind::taubin) step(o.mu);
    st.iterations = it + 1;
    progress.add(1);
  }
  st.last_max_change = n ? *std::max_element(change.begin(), change.end()) : 0.0;
  mesh.normals.clear();
  st.seconds = seconds_since(t0);
  return st;
}

}  // namespace voxpress
