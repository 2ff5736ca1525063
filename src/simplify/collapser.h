// The simplifier's state and its checked edge collapse (private; the
// contract is voxpress/simplify/simplify.h).
//
// Positions live twice: physical (the quadrics, the error, the output) and
// lattice index space (the samples, the clearance). A collapse removes
// vertex u and keeps v at q; it is tried as two straight moves, u to q and
// then v to q, and a sample can change side only if one of the moving
// triangles sweeps over it (the tetrahedron of a triangle whose one corner
// moves), so no sample in any swept tetrahedron, and none within the
// clearance of the final triangles, means every sample keeps its side.
#pragma once

#include <algorithm>
#include <cstdint>
#include <queue>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "simplify/error_quadric.h"
#include "simplify/face_grid.h"
#include "voxpress/simplify/simplify.h"

namespace voxpress::detail {

class Collapser {
 public:
  Collapser(Mesh& mesh, const SimplifyOptions& options);
  SimplifyStats run(std::vector<uint32_t>* vertex_map);

 private:
  /// Remove u, keep v at q (physical).
  struct Move {
    double cost, len2;
    uint32_t u, v;
    Vec3 q;
  };
  struct Entry {
    double cost, len2;
    uint32_t a, b, sa, sb;
    // A max-heap of this order pops the cheapest.
    bool operator<(const Entry& e) const {
      if (cost != e.cost) return cost > e.cost;
      if (len2 != e.len2) return len2 > e.len2;
      return a != e.a ? a > e.a : b > e.b;
    }
  };
  enum : uint8_t { kSharp = 1, kBorder = 2 };  // feature edge flags (a junction edge is a border)
  static constexpr uint8_t kPinned = 255;      // fdeg of a vertex that never moves (a pinch)
  static uint64_t key(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; }

  /// What checking one move finds and needs (one per move in a round, so
  /// that the moves of a round are checked in parallel): the faces around
  /// u or v (`ring`, sorted), those on the edge (`shared`), u's neighbours,
  /// the removed input vertices' new faces, and the box of the new faces
  /// grown by the clearance (index space).
  struct Probe {
    std::vector<uint32_t> ring, shared, nu, nv, common;
    std::vector<std::pair<uint32_t, uint32_t>> assign;  // (input vertex, face)
    std::vector<std::tuple<uint64_t, uint32_t, int>> hits;  // samples_ok's swept samples: (sample key, face class, sign)
    Vec3 lo, hi;
    bool planar = false;  // the last check proved the move inside one plane (in_plane)
    bool is_shared(uint32_t f) const { return std::find(shared.begin(), shared.end(), f) != shared.end(); }
  };
  enum class Verdict : uint8_t { ok, topology, shape, error, samples, clash };
  /// An edge of the heap taken into a round: its moves, cheapest first (and
  /// the lifted ones, lift()), and the first that passed its checks (-1: none).
  struct Candidate {
    uint32_t a = 0, b = 0;  // the edge (its moves are made in the round's parallel checks)
    Move mv[5];
    Verdict verdict[5];
    int n = 0, accepted = -1;
    Probe probe;
  };

  // collapser.cpp
  void build();
  /// The edge's moves, cheapest first, into out[0..3).
  int moves(uint32_t a, uint32_t b, Move* out) const;
  /// The heap entry of edge (a, b): its cheapest move's cost; false when it has no move.
  bool entry_of(uint32_t a, uint32_t b, Entry& out) const;
  int lift(const Move& m, Move* out) const;
  bool removable(uint32_t u, uint32_t v) const;
  // The moves' heap. Its entries go stale as their ends change (a stamp or
  // a removal) and are dropped when popped; prune() drops them all at once
  // (on the 256^3 CAD part at 2 % of its faces, 1.76 M of 2.1 M pops were
  // stale: perf, `press --faces`).
  struct Heap : std::priority_queue<Entry> {
    Heap(std::vector<Entry> v) : std::priority_queue<Entry>(std::less<Entry>(), std::move(v)) {}
    template <class Stale>
    void prune(Stale stale) {
      c.erase(std::remove_if(c.begin(), c.end(), stale), c.end());
      std::make_heap(c.begin(), c.end(), comp);
    }
  };
  bool stale(const Entry& e) const {
    return !vertex_alive[e.a] || !vertex_alive[e.b] || stamp[e.a] != e.sa || stamp[e.b] != e.sb;
  }
  size_t select(Heap& heap, uint64_t want);
  void apply(const Move& m, const Probe& p);
  void recount(uint32_t v);
  void count(Verdict v);
  /// v's neighbours, sorted, each once.
  void neighbours(uint32_t v, std::vector<uint32_t>& out) const;
  void rebuild_grid();
  void compact(std::vector<uint32_t>* vertex_map);
  // collapse_checks.cpp: pure functions of the state (a round's moves are
  // checked in parallel against the state before the round).
  Verdict check(const Move& m, Probe& p) const;
  bool topology_ok(uint32_t u, uint32_t v, Probe& p) const;
  bool shape_ok(const Move& m, const Vec3& qi, const Probe& p) const;
  bool error_ok(const Move& m, Probe& p) const;
  bool samples_ok(const Move& m, const Vec3& qi, Probe& p) const;
  bool clash_free(const Move& m, const Vec3& qi, Probe& p) const;
  bool in_plane(const Move& m, const Vec3& qi, Probe& p) const;
  void box_of(uint32_t f, Vec3& lo, Vec3& hi) const;
  Vec3 at_index(uint32_t w, const Move& m, const Vec3& qi) const { return w == m.u || w == m.v ? qi : xi[w]; }
  Vec3 at_phys(uint32_t w, const Move& m) const { return w == m.u || w == m.v ? m.q : xp[w]; }

  Mesh& mesh;
  const SimplifyOptions& o;
  SimplifyStats st;
  std::vector<Vec3> xp, xi, input;  // physical, index space, the input's physical positions
  std::vector<Triangle>& tri;
  std::vector<std::vector<uint32_t>> vf;  // faces around each vertex
  std::vector<uint8_t> face_alive, vertex_alive, moved;
  std::vector<uint32_t> stamp;
  std::vector<ErrorQuadric> Q;
  std::unordered_map<uint64_t, uint8_t> feature;  // edge key -> kSharp | kBorder
  std::vector<uint8_t> fdeg;                       // feature edges at each vertex (capped at 255)
  std::vector<std::vector<uint32_t>> attached;     // per face: removed input vertices nearest to it
  // With junctions (a shared surface): per face, the class of its face
  // attributes (one per label pair); empty otherwise. A face's attributes
  // never change, so neither does its class.
  std::vector<uint32_t> face_class;
  FaceGrid grid;
  uint64_t grid_faces = 0;  // alive faces when the grid was last built
  double delta = 0;                                // index-space clearance
  // Samples are keyed by their offset from key_base (the mesh's box less
  // kKeyRoom cells), 21 bits per axis; a sweep reaching past that range is
  // refused (conservative).
  static constexpr int64_t kKeyRoom = 1 << 10;
  Vec3 key_base = Vec3::Zero();
  uint64_t alive_faces = 0;
  std::vector<Candidate> round_;      // the moves of the current round
  std::vector<uint32_t> claim_;       // per vertex: the last round whose footprint holds it
  uint32_t round_id_ = 0;
  std::vector<uint32_t> around, keep_, from_u_;  // scratch of the serial steps
  std::vector<std::pair<uint32_t, uint8_t>> carried_;
};

}  // namespace voxpress::detail
