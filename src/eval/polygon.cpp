#include "polygon.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "../core/predicates.h"

namespace voxpress::detail {
namespace {

struct Node {
  uint32_t id;  // index into the concatenated input
  Point2 p;
  int prev, next;
  bool removed = false;
};

int orient(const Point2& a, const Point2& b, const Point2& c) { return orient2d(a.x, a.y, b.x, b.y, c.x, c.y); }
bool same(const Point2& a, const Point2& b) { return a.x == b.x && a.y == b.y; }

// p inside or on the closed triangle (a, b, c) (counter-clockwise).
bool in_triangle(const Point2& a, const Point2& b, const Point2& c, const Point2& p) {
  return orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0;
}

}  // namespace

std::vector<std::array<uint32_t, 3>> triangulate_polygon(const std::vector<Point2>& outer,
                                                         const std::vector<std::vector<Point2>>& holes) {
  std::vector<Node> nodes;
  auto add_loop = [&](const std::vector<Point2>& loop, uint32_t base) {
    const int first = int(nodes.size()), n = int(loop.size());
    for (int i = 0; i < n; ++i)
      nodes.push_back({base + uint32_t(i), loop[size_t(i)], first + (i + n - 1) % n, first + (i + 1) % n});
    return first;
  };
  uint32_t base = 0;
  const int start = add_loop(outer, base);
  base += uint32_t(outer.size());
  std::vector<std::pair<int, int>> hole_rightmost;  // (node, hole index)
  for (size_t h = 0; h < holes.size(); ++h) {
    const int first = add_loop(holes[h], base);
    base += uint32_t(holes[h].size());
    int best = first;
    for (int i = first; i < first + int(holes[h].size()); ++i)
      if (nodes[size_t(i)].p.x > nodes[size_t(best)].p.x) best = i;
    hole_rightmost.push_back({best, int(h)});
  }
  std::sort(hole_rightmost.begin(), hole_rightmost.end(),
            [&](auto a, auto b) { return nodes[size_t(a.first)].p.x > nodes[size_t(b.first)].p.x; });

  auto duplicate = [&](int i) {
    Node copy = nodes[size_t(i)];
    nodes.push_back(copy);
    return int(nodes.size() - 1);
  };
  // Bridges, rightmost hole first.
  for (auto [m, h] : hole_rightmost) {
    (void)h;
    const Point2 M = nodes[size_t(m)].p;
    double best_x = INFINITY;
    int edge = -1;
    int i = start;
    do {
      const Point2 &a = nodes[size_t(i)].p, &b = nodes[size_t(nodes[size_t(i)].next)].p;
      if ((a.y <= M.y && M.y <= b.y) || (b.y <= M.y && M.y <= a.y)) {
        const double x = a.y == b.y ? std::max(a.x, b.x) : a.x + (M.y - a.y) * (b.x - a.x) / (b.y - a.y);
        if (x >= M.x && x < best_x) {
          best_x = x;
          edge = i;
        }
      }
      i = nodes[size_t(i)].next;
    } while (i != start);
    if (edge < 0) throw std::logic_error("hole outside the outer boundary");
    const int ea = edge, eb = nodes[size_t(edge)].next;
    int p = nodes[size_t(ea)].p.x >= nodes[size_t(eb)].p.x ? ea : eb;
    const Point2 I{best_x, M.y};
    if (!same(nodes[size_t(p)].p, I)) {
      // A reflex vertex inside triangle (M, I, P) would block the bridge: take
      // the one making the smallest angle with the ray.
      Point2 tri[3] = {M, I, nodes[size_t(p)].p};
      if (orient(tri[0], tri[1], tri[2]) < 0) std::swap(tri[1], tri[2]);
      double best_cos = -2;
      i = start;
      do {
        const Node& n = nodes[size_t(i)];
        const bool reflex = orient(nodes[size_t(n.prev)].p, n.p, nodes[size_t(n.next)].p) < 0;
        if (reflex && i != p && in_triangle(tri[0], tri[1], tri[2], n.p)) {
          const double dx = n.p.x - M.x, dy = n.p.y - M.y;
          const double c = dx / std::hypot(dx, dy);
          if (c > best_cos) {
            best_cos = c;
            p = i;
          }
        }
        i = nodes[size_t(i)].next;
      } while (i != start);
    }
    // Splice: P -> M -> hole ... -> M' -> P' -> (P's old next).
    const int p2 = duplicate(p), m2 = duplicate(m);
    const int p_next = nodes[size_t(p)].next, m_prev = nodes[size_t(m)].prev;
    nodes[size_t(p)].next = m;
    nodes[size_t(m)].prev = p;
    nodes[size_t(m_prev)].next = m2;
    nodes[size_t(m2)].prev = m_prev;
    nodes[size_t(m2)].next = p2;
    nodes[size_t(p2)].prev = m2;
    nodes[size_t(p2)].next = p_next;
    nodes[size_t(p_next)].prev = p2;
  }

  // Ear clipping.
  std::vector<std::array<uint32_t, 3>> out;
  int remaining = int(outer.size());
  for (const auto& h : holes) remaining += int(h.size()) + 2;
  auto reflex = [&](int i) {
    const Node& n = nodes[size_t(i)];
    return orient(nodes[size_t(n.prev)].p, n.p, nodes[size_t(n.next)].p) <= 0;
  };
  auto is_ear = [&](int i) {
    const Node& n = nodes[size_t(i)];
    const Point2 &a = nodes[size_t(n.prev)].p, &b = n.p, &c = nodes[size_t(n.next)].p;
    if (orient(a, b, c) <= 0) return false;
    const double xlo = std::min({a.x, b.x, c.x}), xhi = std::max({a.x, b.x, c.x});
    const double ylo = std::min({a.y, b.y, c.y}), yhi = std::max({a.y, b.y, c.y});
    for (int j = nodes[size_t(n.next)].next; j != n.prev; j = nodes[size_t(j)].next) {
      const Point2& q = nodes[size_t(j)].p;
      if (q.x < xlo || q.x > xhi || q.y < ylo || q.y > yhi) continue;
      if (same(q, a) || same(q, b) || same(q, c)) continue;
      if (reflex(j) && in_triangle(a, b, c, q)) return false;
    }
    return true;
  };
  int cur = start, since_clip = 0;
  while (remaining > 3) {
    if (is_ear(cur)) {
      Node& n = nodes[size_t(cur)];
      out.push_back({nodes[size_t(n.prev)].id, n.id, nodes[size_t(n.next)].id});
      nodes[size_t(n.prev)].next = n.next;
      nodes[size_t(n.next)].prev = n.prev;
      n.removed = true;
      --remaining;
      cur = n.prev;
      since_clip = 0;
    } else {
      cur = nodes[size_t(cur)].next;
      if (++since_clip > 2 * remaining) throw std::logic_error("ear clipping stalled (self-intersecting polygon?)");
    }
  }
  const Node& n = nodes[size_t(cur)];
  if (orient(nodes[size_t(n.prev)].p, n.p, nodes[size_t(n.next)].p) > 0)
    out.push_back({nodes[size_t(n.prev)].id, n.id, nodes[size_t(n.next)].id});
  return out;
}

}  // namespace voxpress::detail
