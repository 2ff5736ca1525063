// A label map's shared surface simplified once (issue 76, item 3): both
// labels of an interface keep the same triangles, the junction lines (edges
// of three and more triangles) and the borders between different label
// pairs stay edges, every sample stays on its side of every interface.
#include "voxpress/labels/shared_surface.h"

namespace voxpress {

SimplifyStats simplify_shared(SharedSurface& s, const SimplifyOptions& options) {
  Mesh m = s.mesh;
  // The label pair of each triangle as face attributes: their borders are
  // kept, and they follow the surviving triangles. An interface may hold
  // triangles of both orders, (a, b) and (b, a) wound the other way: each
  // is first written with the lower label inside (its winding reversed if
  // need be), so one interface is one oriented sheet with one pair.
  MeshAttribute in{"in", ScalarType::u32, {}}, out{"out", ScalarType::u32, {}};
  in.values.reserve(s.sides.size());
  out.values.reserve(s.sides.size());
  for (size_t f = 0; f < s.sides.size(); ++f) {
    auto sd = s.sides[f];
    if (sd[0] > sd[1]) {
      std::swap(sd[0], sd[1]);
      std::swap(m.triangles[f][1], m.triangles[f][2]);
    }
    in.values.push_back(double(sd[0]));
    out.values.push_back(double(sd[1]));
  }
  m.face_attributes.push_back(std::move(in));
  m.face_attributes.push_back(std::move(out));
  SimplifyOptions o = options;
  o.lattice = &s.lattice;
  o.junctions = true;
  std::vector<uint32_t> kept;
  const SimplifyStats st = simplify(m, o, &kept);
  const MeshAttribute& a = m.face_attributes[m.face_attributes.size() - 2];
  const MeshAttribute& b = m.face_attributes.back();
  s.sides.resize(m.triangles.size());
  for (size_t f = 0; f < m.triangles.size(); ++f) s.sides[f] = {uint32_t(a.values[f]), uint32_t(b.values[f])};
  m.face_attributes.resize(m.face_attributes.size() - 2);
  for (size_t v = 0; v < kept.size(); ++v)
    if (kept[v] != UINT32_MAX) {
      s.kind[kept[v]] = s.kind[v];
      s.corner[kept[v]] = s.corner[v];
    }
  s.kind.resize(m.positions.size());
  s.corner.resize(m.positions.size());
  s.apexes.clear();  // the vertices have moved off their midpoint places
  s.mesh = std::move(m);
  return st;
}

}  // namespace voxpress
