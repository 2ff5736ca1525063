// Closest points, segment crossings and area sampling on a triangle mesh
// (private; behind Truth and the metrics).
//
// A BVH over the faces (bvh.h). Long thin faces (ear-clipped planar faces,
// CAD exports) have boxes that overlap everything near them and ruin
// pruning, so the query structure splits any face whose box diagonal exceeds
// max(4 x the median, 1/16 of the mesh's) by longest-edge bisection into
// pieces that keep the face's id; the mesh itself is untouched, and the
// closest point over the pieces is the closest point on the face.
// closest() is a best-first descent that visits
// the nearer child first and prunes boxes farther than the best distance so
// far; the point-triangle step is Ericson's Voronoi-region test (Real-Time
// Collision Detection, 5.1.5). segment_hits() collects every face crossing
// of a segment (Moller-Trumbore). Samples are uniform by area: a face is
// drawn from the cumulative area table, then a point uniformly inside it.
// All queries are const and thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include "../core/bvh.h"
#include "voxpress/core/mesh.h"

namespace voxpress::detail {

class MeshQuery {
 public:
  explicit MeshQuery(const Mesh& mesh);

  struct Hit {
    Vec3 point;
    uint32_t face = 0;
    double dist2 = 0;
  };
  Hit closest(const Vec3& p) const;
  /// Like closest(), but when several faces are equally close (the closest
  /// point is on an edge or a vertex), returns the one whose normal is best
  /// aligned with `hint`.
  Hit closest(const Vec3& p, const Vec3& hint) const;
  /// Parameters s in [0, 1] where segment a + s (b - a) meets a face, unsorted
  /// (a crossing exactly on an edge between pieces may be listed twice).
  void segment_hits(const Vec3& a, const Vec3& b, std::vector<double>& out) const;
  /// Unit normal of face f (zero for a degenerate face).
  const Vec3& normal(uint32_t f) const { return normals_[f]; }
  double area() const { return cumulative_.empty() ? 0 : cumulative_.back(); }
  /// Point number `index` of a deterministic uniform-by-area sequence.
  Hit sample(uint64_t seed, uint64_t index) const;
  const Mesh& mesh() const { return mesh_; }
  size_t faces() const { return mesh_.triangles.size(); }
  size_t pieces() const { return prims_.size(); }

 private:
  struct Piece {
    Vec3 a, b, c;
    uint32_t face;
  };
  // A BVH primitive: a whole face (piece < 0) or a piece of a split face.
  struct Prim {
    uint32_t face;
    int32_t piece;
  };
  void make_prims();
  void corners(const Prim& p, const Vec3*& a, const Vec3*& b, const Vec3*& c) const {
    if (p.piece < 0) {
      const auto& t = mesh_.triangles[p.face];
      a = &mesh_.positions[t[0]];
      b = &mesh_.positions[t[1]];
      c = &mesh_.positions[t[2]];
    } else {
      const Piece& q = pieces_[size_t(p.piece)];
      a = &q.a;
      b = &q.b;
      c = &q.c;
    }
  }
  std::vector<Aabb> prim_boxes() const;

  const Mesh& mesh_;
  std::vector<Prim> prims_;
  std::vector<Piece> pieces_;  // only for faces that were split
  std::vector<Vec3> normals_;
  std::vector<double> cumulative_;  // prefix sums of face areas
  Bvh bvh_;
};

/// Closest point of triangle (a, b, c) to p.
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Deterministic counter-based uniform doubles in [0, 1): value number `index` of stream `seed`.
double uniform(uint64_t seed, uint64_t index);

}  // namespace voxpress::detail
