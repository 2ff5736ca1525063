// Derivation of the marching-squares and marching-cubes cases from the face
// rule. Theory of operation: see include/voxpress/extract/cube_cases.h and
// docs/ARCHITECTURE.md ("The face rule"). Runs once, on first use (~ms).
#include "voxpress/extract/cube_cases.h"

#include <algorithm>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "../core/predicates.h"
#include "case_geometry.h"
#include "voxpress/core/types.h"

namespace voxpress {
namespace {

using namespace detail;  // the derivation's geometry (case_geometry.h)

// ---------------------------------------------------------------- 2D rule
std::array<SquareCase, 16> derive_squares() {
  std::array<SquareCase, 16> cases{};
  for (unsigned mask = 0; mask < 16; ++mask) {
    SquareCase& sc = cases[mask];
    auto inside = [&](int s) { return (mask >> (s & 3)) & 1; };
    // Each inside corner i with both neighbours outside is cut off alone by
    // the segment (edge i -> edge i-1). This covers the diagonal (ambiguous)
    // case: the face rule separates the two inside corners.
    // Otherwise the contour is the single segment between the two sticks.
    int sticks[4], n = 0;
    for (int s = 0; s < 4; ++s)
      if (inside(s) != inside(s + 1)) sticks[n++] = s;
    if (n == 0) continue;
    if (n == 4) {
      for (int i = 0; i < 4; ++i)
        if (inside(i)) sc.segments[sc.count++] = {uint8_t(i), uint8_t((i + 3) & 3)};
      continue;
    }
    // n == 2: one segment between the two sticks, oriented with the inside
    // corner on its left (checked geometrically on the unit square).
    const int a = sticks[0], b = sticks[1];
    auto mid = [](int s) {
      static const double m[4][2] = {{0.5, 0}, {1, 0.5}, {0.5, 1}, {0, 0.5}};
      return std::array<double, 2>{m[s][0], m[s][1]};
    };
    static const double corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const int in_corner = inside(a) ? a : (a + 1) & 3;
    const auto p = mid(a), q = mid(b);
    const int side = detail::orient2d(p[0], p[1], q[0], q[1], corner[in_corner][0], corner[in_corner][1]);
    if (side > 0)
      sc.segments[sc.count++] = {uint8_t(a), uint8_t(b)};
    else
      sc.segments[sc.count++] = {uint8_t(b), uint8_t(a)};
  }
  return cases;
}

constexpr int kRobustnessSamples = 64;

CubeCase derive_cube(unsigned mask, const std::array<Face, 6>& faces, const std::array<SquareCase, 16>& squares) {
  CubeCase cc;
  // 1. Oriented face segments. square_case orients them counter-clockwise
  // seen from +axis (inside on the left); a cell's boundary loops must run
  // counter-clockwise seen from outside the cell, which is -axis for side 0.
  int next[12];
  std::fill(next, next + 12, -1);
  for (const Face& f : faces) {
    unsigned m = 0;
    for (int s = 0; s < 4; ++s) m |= ((mask >> f.corner[s]) & 1u) << s;
    const SquareCase& sc = squares[m];
    for (int k = 0; k < sc.count; ++k) {
      int from = f.edge[sc.segments[k][0]], to = f.edge[sc.segments[k][1]];
      if (f.side == 1) std::swap(from, to);
      if (next[from] != -1) throw std::logic_error("face segments do not form loops");
      next[from] = to;
    }
  }
  // 2. Loops.
  std::vector<std::vector<int>> loops;
  bool seen[12] = {};
  for (int e = 0; e < 12; ++e) {
    if (next[e] < 0 || seen[e]) continue;
    std::vector<int> loop;
    for (int x = e; !seen[x]; x = next[x]) {
      if (next[x] < 0) throw std::logic_error("open loop");
      seen[x] = true;
      loop.push_back(x);
    }
    loops.push_back(loop);
  }
  cc.loops = uint8_t(loops.size());
  if (loops.empty()) return cc;

  // 3. Candidate triangulations per loop, combined across loops.
  std::vector<std::vector<std::vector<Tri>>> options(loops.size());
  for (size_t l = 0; l < loops.size(); ++l) triangulations(loops[l], options[l]);

  std::array<Vec3, 12> mid;
  for (int e = 0; e < 12; ++e) mid[e] = edge_point(e, 0.5);
  std::vector<std::array<Vec3, 12>> samples(kRobustnessSamples);
  uint64_t seed = 0x5eed0000ull + mask;
  for (auto& s : samples)
    for (int e = 0; e < 12; ++e) s[e] = edge_point(e, 0.02 + 0.96 * double(splitmix(seed) >> 11) * 0x1.0p-53);

  std::vector<Tri> best;
  int best_robust = -1;
  double best_area = 0;
  std::vector<size_t> pick(loops.size(), 0);
  for (;;) {
    std::vector<Tri> tris;
    for (size_t l = 0; l < loops.size(); ++l)
      for (const Tri& t : options[l][pick[l]]) tris.push_back(t);
    if (valid_geometry(tris, mid)) {
      int robust = 0;
      for (const auto& s : samples) robust += valid_geometry(tris, s) ? 1 : 0;
      const double area = total_area(tris, mid);
      if (robust > best_robust || (robust == best_robust && area < best_area - 1e-12)) {
        best = tris;
        best_robust = robust;
        best_area = area;
      }
    }
    size_t l = 0;
    while (l < loops.size() && ++pick[l] == options[l].size()) pick[l++] = 0;
    if (l == loops.size()) break;
  }
  if (best_robust < 0) throw std::logic_error("no valid triangulation for cube case " + std::to_string(mask));
  cc.count = uint8_t(best.size());
  for (size_t i = 0; i < best.size(); ++i) cc.triangles[i] = best[i];
  return cc;
}

struct Tables {
  std::array<SquareCase, 16> squares;
  std::array<CubeCase, 256> cubes;
  Tables() {
    squares = derive_squares();
    const auto faces = make_faces();
    for (unsigned m = 0; m < 256; ++m) cubes[m] = derive_cube(m, faces, squares);
  }
};

const Tables& tables() {
  static const Tables t;  // thread-safe one-time initialisation
  return t;
}

}  // namespace

const SquareCase& square_case(unsigned mask) { return tables().squares[mask & 15]; }
const CubeCase& cube_case(unsigned mask) { return tables().cubes[mask & 255]; }

}  // namespace voxpress
