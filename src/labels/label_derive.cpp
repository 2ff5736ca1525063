// Derivation of one label case: the cube's face segments, their patches
// and junctions, and the search for the most robust valid triangulation
// (theory: include/voxpress/labels/label_cases.h).
#include "labels/label_derive.h"

#include <algorithm>
#include <functional>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

#include "../extract/case_geometry.h"
#include "voxpress/extract/cube_cases.h"

namespace voxpress {
namespace {

using detail::Tri;

// Random positions tried per candidate triangulation (the binary derivation
// tries 64 over 256 cases; label patterns number in the thousands per volume).
constexpr int kLabelRobustnessSamples = 12;
// Complete candidate triangulations ranked per case (the search stops
// there): each costs kLabelRobustnessSamples validity checks.
constexpr size_t kMaxCombinations = 16;
// Choices of alternatives (loop disc or fan, junction edges or fan) tried
// per case: the product over its components, capped.
constexpr size_t kMaxChoices = 256;
// Sets of junction edges kept per component: cubes of eight labels have
// six centres of four labels and thousands of sets; keeping 256 instead of
// the first 4 that close up derived no more of 2000 random patterns.
constexpr size_t kMaxJunctionAlternatives = 4;
// Complete sets of junction edges tried per component (a bound on the
// enumeration's time for cubes of many labels; refused past it).
constexpr size_t kMaxJunctionSets = 512;

struct Seg {
  int from, to;
  uint8_t in, out;
};

using detail::distinct_count;

// The face segments, oriented as the binary derivation orients them (in on
// the left in the square frame, reversed on side-1 faces), then each with
// its smaller label as `in` (a segment reversed swaps its sides).
std::vector<Seg> face_segments(const LabelPattern& r, const std::array<detail::Face, 6>& faces) {
  std::vector<Seg> segs;
  for (int f = 0; f < 6; ++f) {
    const detail::Face& F = faces[size_t(f)];
    std::array<uint8_t, 4> lab{};
    for (int s = 0; s < 4; ++s) lab[size_t(s)] = r[size_t(F.corner[s])];
    auto add = [&](int a, int b, uint8_t in, uint8_t out) {
      if (F.side == 1) std::swap(a, b);
      if (in > out) std::swap(a, b), std::swap(in, out);  // one orientation per pair: the smaller label on the left
      segs.push_back({a, b, in, out});
    };
    const int k = distinct_count(lab.data(), 4);
    if (k == 1) continue;
    if (k == 2) {
      const uint8_t hi = *std::max_element(lab.begin(), lab.end()), lo = *std::min_element(lab.begin(), lab.end());
      unsigned mask = 0;
      for (int s = 0; s < 4; ++s) mask |= unsigned(lab[size_t(s)] == hi) << s;
      const SquareCase& sc = square_case(mask);
      for (int i = 0; i < sc.count; ++i) add(F.edge[sc.segments[size_t(i)][0]], F.edge[sc.segments[size_t(i)][1]], hi, lo);
      continue;
    }
    if (!face_has_center(lab)) {  // three labels, the equal pair diagonal: it joins, the others are cut off
      const uint8_t x = lab[0] == lab[2] ? lab[0] : lab[1];
      for (int i = 0; i < 4; ++i)
        if (lab[size_t(i)] != x) add(F.edge[i], F.edge[(i + 3) & 3], lab[size_t(i)], x);
      continue;
    }
    for (int s = 0; s < 4; ++s)  // from each stick to the centre, corner s's label on the left
      if (lab[size_t(s)] != lab[size_t((s + 1) & 3)]) add(F.edge[s], kFaceCenter + f, lab[size_t(s)], lab[size_t((s + 1) & 3)]);
  }
  return segs;
}

// One group of triangles to choose among: the candidates of a loop or of a
// patch, all with the same sides; or a fixed fan.
struct Group {
  std::vector<std::vector<Tri>> options;
  uint8_t in = 0, out = 0;
};

int find(std::vector<int>& parent, int x) {
  while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
  return x;
}

// Directed edges (from, to) as disjoint cycles, each from its first edge's
// start: false when a vertex starts two edges or a walk does not close on
// its start (an open chain, or one running into another cycle).
bool cycles_of(const std::vector<std::pair<int, int>>& edges, std::vector<std::vector<int>>& out) {
  std::map<int, int> next;
  for (const auto& [a, b] : edges)
    if (!next.emplace(a, b).second) return false;
  std::map<int, bool> seen;
  out.clear();
  for (const auto& e : edges) {
    if (seen[e.first]) continue;
    std::vector<int> loop;
    int x = e.first;
    while (!seen[x]) {
      seen[x] = true;
      loop.push_back(x);
      const auto it = next.find(x);
      if (it == next.end()) return false;
      x = it->second;
    }
    if (x != e.first) return false;
    out.push_back(std::move(loop));
  }
  return true;
}

std::vector<std::pair<int, int>> edges_of(const std::vector<Seg>& segs) {
  std::vector<std::pair<int, int>> edges;
  for (const Seg& s : segs) edges.push_back({s.from, s.to});
  return edges;
}

// Segments that must form one directed cycle: its vertices, or throws.
std::vector<int> cycle_of(const std::vector<Seg>& segs) {
  std::vector<std::vector<int>> loops;
  if (!cycles_of(edges_of(segs), loops) || loops.size() != 1)
    throw std::logic_error("label case: a loop's segments are not one cycle");
  return loops[0];
}

// Labels around a centre (bit set of ranks) and its degree.
std::pair<unsigned, int> center_labels(const std::vector<Seg>& cs, int c) {
  unsigned labels = 0;
  int degree = 0;
  for (const Seg& s : cs)
    if (s.from == c || s.to == c) labels |= (1u << s.in) | (1u << s.out), ++degree;
  return {labels, degree};
}

// The patches of a junction component for a set of junction edges, or
// false when its segments and junction edges do not close into cycles. A
// junction edge carries the labels both its centres have (three); the
// patch of a pair of them runs along it. Per pair, each chain's end is
// joined to a chain's start by a path of its junction edges (through a
// centre of four labels, a path has two).
struct Patch {
  std::vector<int> loop;
  uint8_t in = 0, out = 0;
};

bool patches_for(const std::vector<Seg>& cs, const std::vector<std::pair<int, int>>& junctions, std::vector<Patch>& out) {
  std::map<std::pair<uint8_t, uint8_t>, std::vector<Seg>> pairs;
  for (const Seg& s : cs) pairs[{s.in, s.out}].push_back(s);
  std::vector<unsigned> carries;
  for (const auto& [x, y] : junctions) {
    const unsigned t = (x == kApex ? ~0u : center_labels(cs, x).first) & (y == kApex ? ~0u : center_labels(cs, y).first);
    if (__builtin_popcount(t) != 3) return false;
    carries.push_back(t);
  }
  out.clear();
  for (const auto& [ab, ps] : pairs) {
    const unsigned both = (1u << ab.first) | (1u << ab.second);
    std::vector<Seg> closed = ps;
    std::map<int, int> balance;  // out - in per vertex
    for (const Seg& s : ps) ++balance[s.from], --balance[s.to];
    std::vector<size_t> mine;  // junction edges this pair's patch runs along
    for (size_t j = 0; j < junctions.size(); ++j)
      if ((carries[j] & both) == both) mine.push_back(j);
    std::vector<bool> used(mine.size(), false);
    // From each chain end (balance < 0) along unused junction edges to a chain start (balance > 0).
    for (auto& entry : balance) {
      const int v = entry.first;
      int& bal = entry.second;
      while (bal < 0) {
        int x = v;
        std::vector<std::pair<int, int>> path;
        std::function<bool(int)> walk = [&](int at) -> bool {
          if (at != v && balance[at] > 0) {
            --balance[at];
            return true;
          }
          for (size_t k = 0; k < mine.size(); ++k) {
            if (used[k]) continue;
            const auto [p, q] = junctions[mine[k]];
            if (p != at && q != at) continue;
            const int to = p == at ? q : p;
            used[k] = true;
            path.push_back({at, to});
            if (walk(to)) return true;
            path.pop_back();
            used[k] = false;
          }
          return false;
        };
        if (!walk(x)) return false;
        for (const auto& [from, to] : path) closed.push_back({from, to, ab.first, ab.second});
        ++bal;
      }
    }
    for (bool u : used)
      if (!u) return false;  // a junction edge that no patch of the pair closes along
    // Cycles: every vertex now has one segment in and one out.
    std::vector<std::vector<int>> loops;
    if (!cycles_of(edges_of(closed), loops)) return false;
    for (auto& loop : loops) {
      if (loop.size() < 3) return false;
      out.push_back({std::move(loop), ab.first, ab.second});
    }
  }
  return true;
}

// The topological part of label_case_defect on patches before they are
// triangulated: per label, every edge inside the cube used once each way,
// and around each apex the patches' fans chain into one cycle (a polygon's
// fan at the apex runs from the vertex after it to the one before).
bool patches_close_up(const std::vector<Patch>& patches) {
  for (int L = 0; L < 8; ++L) {
    std::map<std::pair<int, int>, int> directed;
    std::map<int, std::vector<std::pair<int, int>>> links;  // per apex: its fans' chords
    bool any = false;
    for (const Patch& p : patches) {
      if (p.in != L && p.out != L) continue;
      any = true;
      std::vector<int> loop = p.loop;
      if (p.out == L) std::reverse(loop.begin(), loop.end());
      const size_t k = loop.size();
      for (size_t i = 0; i < k; ++i) {
        const int a = loop[i], b = loop[(i + 1) % k];
        if ((detail::vertex_faces(a) & detail::vertex_faces(b)) == 0) directed[{a, b}]++;
        if (a >= kApex) links[a].push_back({loop[(i + 1) % k], loop[(i + k - 1) % k]});
      }
    }
    if (!any) continue;
    for (const auto& [e, n] : directed) {
      const auto back = directed.find({e.second, e.first});
      if (n != 1 || back == directed.end() || back->second != 1) return false;
    }
    std::vector<std::vector<int>> loops;
    for (const auto& [apex, link] : links)
      if (!cycles_of(link, loops) || loops.size() != 1) return false;
  }
  return true;
}

// Every set of junction edges of a component (a centre of three labels
// ends one, a centre of four ends one or two; at most 6 centres) whose
// patches close up per label: the alternatives the triangulation search
// chooses among.
std::vector<std::vector<Group>> junction_patches(const std::vector<Seg>& cs, const std::vector<int>& centers) {
  std::vector<std::vector<Group>> alternatives;
  std::vector<int> degree;
  std::vector<unsigned> labels;
  for (int c : centers) {
    const auto [l, d] = center_labels(cs, c);
    labels.push_back(l);
    degree.push_back(d);
  }
  size_t tried = 0;  // complete sets of junction edges evaluated
  std::vector<int> ends(centers.size(), 0);  // junction edges at each centre so far
  std::vector<std::pair<int, int>> junctions;
  std::function<void(size_t)> extend = [&](size_t i) {
    if (alternatives.size() >= kMaxJunctionAlternatives || tried >= kMaxJunctionSets) return;
    while (i < centers.size() && ends[i] >= degree[i] - 2) ++i;
    if (i == centers.size()) {
      ++tried;
      std::vector<Patch> patches;
      if (!patches_for(cs, junctions, patches) || !patches_close_up(patches)) return;
      std::vector<Group> groups;
      for (const Patch& p : patches) {
        Group g;
        g.in = p.in;
        g.out = p.out;
        detail::triangulations(p.loop, g.options);
        if (g.options.empty()) return;
        groups.push_back(std::move(g));
      }
      alternatives.push_back(std::move(groups));
      return;
    }
    // Centre i still needs an edge; a centre of four may also stop at one.
    if (degree[i] == 4 && ends[i] == 1) {
      ++ends[i];  // stop: one edge only
      extend(i + 1);
      --ends[i];
    }
    for (size_t j = i + 1; j < centers.size(); ++j) {
      if (ends[j] >= degree[j] - 2 || __builtin_popcount(labels[i] & labels[j]) != 3) continue;  // a curve of three labels
      ++ends[i], ++ends[j];
      junctions.push_back({centers[i], centers[j]});
      extend(i);
      junctions.pop_back();
      --ends[i], --ends[j];
    }
    // Or to a vertex inside the cube where junction curves meet (four
    // labels at a point): the apex, placed at the centres' centroid.
    if (__builtin_popcount(labels[i]) == 3) {
      ++ends[i];
      junctions.push_back({centers[i], kApex});
      extend(i);
      junctions.pop_back();
      --ends[i];
    }
  };
  extend(0);
  return alternatives;
}

// Per component of the segment graph: its triangulation alternatives (a
// loop's disc, or a junction's sets of patches; the fan from an apex is
// always the last), its fan and its face centres.
struct Components {
  std::vector<std::vector<std::vector<Group>>> alternatives;
  std::vector<std::vector<LabelCase::Triangle>> fans;
  std::vector<std::vector<int>> centers_of;
};

Components components_of(const std::vector<Seg>& segs) {
  // Components of the segment graph over vertices 0..17.
  std::vector<int> parent(18);
  std::iota(parent.begin(), parent.end(), 0);
  for (const Seg& s : segs) parent[size_t(find(parent, s.from))] = find(parent, s.to);
  std::map<int, std::vector<Seg>> components;
  for (const Seg& s : segs) components[find(parent, s.from)].push_back(s);

  // Per component: its loop's disc or its junction's pairings (patches),
  // and last its fan from the cube's centre (one component at most can
  // take the centre: two would pinch the labels between them there).
  Components out;
  for (const auto& [root, cs] : components) {
    std::vector<int> centers;
    for (const Seg& s : cs)
      for (int v : {s.from, s.to})
        if (v >= kFaceCenter && std::find(centers.begin(), centers.end(), v) == centers.end()) centers.push_back(v);
    out.centers_of.push_back(centers);
    out.fans.emplace_back();  // apex id set per choice
    for (const Seg& s : cs) out.fans.back().push_back({{uint8_t(s.from), uint8_t(s.to), uint8_t(kApex)}, s.in, s.out});
    if (centers.empty()) {  // a loop between two labels: a disc on its sticks, or a fan
      Group g;
      g.in = cs[0].in;
      g.out = cs[0].out;
      for (const Seg& s : cs)
        if (s.in != g.in || s.out != g.out) throw std::logic_error("label case: a loop between more than two labels");
      detail::triangulations(cycle_of(cs), g.options);
      out.alternatives.push_back({{std::move(g)}, {}});
      continue;
    }
    // Junction curves: each face centre where three labels meet ends one,
    // whose other end is a centre of the same three labels; for a pairing of
    // the centres, every pair of labels' segments and the junction edges
    // close into cycles, one patch each.
    out.alternatives.push_back(junction_patches(cs, centers));
    out.alternatives.back().push_back({});  // the fan
  }
  return out;
}

// How many components a choice gives their fan (the last alternative).
size_t fan_count(const Components& cp, const std::vector<size_t>& c) {
  size_t n = 0;
  for (size_t j = 0; j < c.size(); ++j) n += c[j] + 1 == cp.alternatives[j].size();
  return n;
}

using Places = std::array<Vec3, kApex + kMaxApexes>;

// The midpoint places (sticks at t = 1/2, face centres and the cube's
// centre fixed) and kLabelRobustnessSamples random ones (sticks anywhere in
// [0.02, 0.98], seeded by the pattern: the same case every run).
std::vector<Places> robustness_samples(const LabelPattern& r, Places& mid) {
  for (int e = 0; e < 12; ++e) mid[size_t(e)] = detail::edge_point(e, 0.5);
  for (int f = 0; f < 6; ++f) {
    Vec3 c(0.5, 0.5, 0.5);
    c[f / 2] = double(f % 2);
    mid[size_t(kFaceCenter + f)] = c;
  }
  uint64_t seed = 0x1abe1ull;
  for (uint8_t x : r) seed = seed * 8 + x;
  std::vector<Places> samples(kLabelRobustnessSamples, mid);
  for (auto& s : samples)
    for (int e = 0; e < 12; ++e) s[size_t(e)] = detail::edge_point(e, 0.02 + 0.96 * double(detail::splitmix(seed) >> 11) * 0x1.0p-53);
  return samples;
}

// The choices of alternatives (one index per component), fewest fans first.
std::vector<std::vector<size_t>> choices_of(const Components& cp) {
  std::vector<std::vector<size_t>> choices(1);
  for (const auto& a : cp.alternatives) {
    std::vector<std::vector<size_t>> next;
    for (const auto& c : choices)
      for (size_t k = 0; k < a.size() && next.size() < kMaxChoices; ++k) {
        next.push_back(c);
        next.back().push_back(k);
      }
    choices = std::move(next);
  }
  std::stable_sort(choices.begin(), choices.end(),
                   [&](const auto& x, const auto& y) { return fan_count(cp, x) < fan_count(cp, y); });
  return choices;
}

// One choice of alternatives made concrete: its groups (apex ids given),
// the fans' triangles and the apexes, placed in mid and every sample.
// False when it needs more than kMaxApexes apexes.
struct Choice {
  std::vector<Group> groups;
  std::vector<LabelCase::Triangle> fan;
  std::vector<Vec3> apexes;
};

bool make_choice(const Components& cp, const std::vector<size_t>& alt, Places& mid, std::vector<Places>& samples,
                 Choice& ch) {
  const auto place = [&](uint8_t id, const Vec3& x) {
    ch.apexes.push_back(x);
    mid[id] = x;
    for (auto& sample : samples) sample[id] = x;
  };
  for (size_t j = 0; j < cp.alternatives.size(); ++j) {
    if (ch.apexes.size() == size_t(kMaxApexes)) return false;
    if (alt[j] + 1 == cp.alternatives[j].size()) {  // a fan from the centroid of its component's vertices
      const uint8_t apex = uint8_t(kApex + ch.apexes.size());
      Vec3 c = Vec3::Zero();
      for (auto t : cp.fans[j]) {
        c += mid[t.v[0]];
        t.v[2] = apex;
        ch.fan.push_back(t);
      }
      place(apex, c / double(cp.fans[j].size()));
    }
    bool apex = false;
    for (const Group& g : cp.alternatives[j][alt[j]])
      for (const auto& o : g.options)
        for (const Tri& t : o) apex = apex || std::find(t.begin(), t.end(), uint8_t(kApex)) != t.end();
    const uint8_t id = uint8_t(kApex + ch.apexes.size());
    if (apex && ch.apexes.size() == size_t(kMaxApexes)) return false;
    if (apex) {  // where the component's junction curves meet: the centroid of its face centres
      Vec3 c = Vec3::Zero();
      int n = 0;
      for (int v : cp.centers_of[j]) c += mid[size_t(v)], ++n;
      place(id, c / double(n));
    }
    for (Group g : cp.alternatives[j][alt[j]]) {
      for (auto& o : g.options)
        for (Tri& t : o)
          for (uint8_t& v : t)
            if (v == kApex) v = id;
      ch.groups.push_back(std::move(g));
    }
  }
  return true;
}

// Depth first over the groups' triangulations, pruned as soon as a partial
// choice intersects itself or makes two patches share an edge; the complete
// choices (up to kMaxCombinations) ranked by robustness over the samples,
// then area. False when none is valid.
bool best_triangulation(const Choice& ch, uint8_t labels, const Places& mid, const std::vector<Places>& samples,
                        std::vector<size_t>& best) {
  const std::vector<Group>& groups = ch.groups;
  for (const Group& g : groups)
    if (g.options.empty()) return false;
  std::vector<Tri> fixed;
  for (const auto& t : ch.fan) fixed.push_back(t.v);
  if (!detail::valid_geometry(fixed, mid)) return false;
  auto assemble = [&](const std::vector<size_t>& p, size_t upto) {
    std::vector<Tri> tris = fixed;
    for (size_t g = 0; g < upto; ++g)
      for (const Tri& t : groups[g].options[p[g]]) tris.push_back(t);
    return tris;
  };
  auto sided = [&](const std::vector<size_t>& p, size_t upto) {
    LabelCase trial;
    trial.labels = labels;
    trial.triangles = ch.fan;
    for (size_t g = 0; g < upto; ++g)
      for (const Tri& t : groups[g].options[p[g]]) trial.triangles.push_back({t, groups[g].in, groups[g].out});
    return trial;
  };
  std::vector<size_t> pick(groups.size(), 0);
  int best_robust = -1;
  double best_area = 0;
  size_t leaves = 0;
  std::function<void(size_t)> search = [&](size_t g) {
    if (g == groups.size()) {
      if (!detail::label_case_defect(sided(pick, g), true).empty()) return;
      const std::vector<Tri> tris = assemble(pick, g);  // valid at the midpoints: checked group by group
      ++leaves;
      int robust = 0;
      for (const auto& sample : samples) robust += detail::valid_geometry(tris, sample) ? 1 : 0;
      const double area = detail::total_area(tris, mid);
      if (robust > best_robust || (robust == best_robust && area < best_area - 1e-12)) {
        best = pick;
        best_robust = robust;
        best_area = area;
      }
      return;
    }
    const std::vector<Tri> before = assemble(pick, g);
    for (size_t o = 0; o < groups[g].options.size() && leaves < kMaxCombinations; ++o) {
      pick[g] = o;
      if (!detail::valid_with(before, groups[g].options[o], mid)) continue;
      if (!detail::label_case_defect(sided(pick, g + 1), false).empty()) continue;
      search(g + 1);
    }
  };
  search(0);
  return best_robust >= 0;
}

}  // namespace

LabelCase detail::derive_label_case(const LabelPattern& r) {
  LabelCase lc;
  const int m = distinct_count(r.data(), 8);
  lc.labels = uint8_t(m);
  if (m < 2) return lc;
  if (m == 2) {  // the binary case, the larger label inside
    unsigned mask = 0;
    for (int c = 0; c < 8; ++c) mask |= unsigned(r[size_t(c)] == 1) << c;
    const CubeCase& cc = cube_case(mask);
    for (int i = 0; i < cc.count; ++i) lc.triangles.push_back({cc.triangles[size_t(i)], 1, 0});
    return lc;
  }
  static const auto faces = detail::make_faces();
  const Components cp = components_of(face_segments(r, faces));
  Places mid{};
  std::vector<Places> samples = robustness_samples(r, mid);
  // The first choice of alternatives (pairings first, fans last) that has
  // any valid triangulation wins (a fan only when no pairing triangulates).
  for (const std::vector<size_t>& alt : choices_of(cp)) {
    if (fan_count(cp, alt) > kMaxApexes) break;
    Choice ch;
    std::vector<size_t> best;
    if (!make_choice(cp, alt, mid, samples, ch) || !best_triangulation(ch, lc.labels, mid, samples, best)) continue;
    lc.apexes = ch.apexes;
    lc.triangles = ch.fan;
    for (size_t g = 0; g < ch.groups.size(); ++g)
      for (const Tri& t : ch.groups[g].options[best[g]]) lc.triangles.push_back({t, ch.groups[g].in, ch.groups[g].out});
    return lc;
  }
  throw std::logic_error("label case: no valid triangulation");
}

int detail::distinct_count(const uint8_t* r, int n) {
  uint8_t seen = 0;
  for (int i = 0; i < n; ++i) seen |= uint8_t(1u << r[i]);
  return __builtin_popcount(seen);
}

std::string detail::label_case_defect(const LabelCase& c, bool complete) {
  for (int L = 0; L < c.labels; ++L) {
    std::map<std::pair<int, int>, int> directed;
    std::map<int, std::vector<std::pair<int, int>>> links;  // per apex: the edges opposite it
    for (const auto& t : c.triangles) {
      if (t.in != L && t.out != L) continue;
      std::array<int, 3> v = {t.v[0], t.v[1], t.v[2]};
      if (t.out == L) std::swap(v[1], v[2]);
      for (int i = 0; i < 3; ++i) {
        const int a = v[size_t(i)], b = v[size_t((i + 1) % 3)];
        if ((detail::vertex_faces(a) & detail::vertex_faces(b)) == 0) directed[{a, b}]++;
        if (a >= kApex) links[a].push_back({b, v[size_t((i + 2) % 3)]});
      }
    }
    for (const auto& [e, n] : directed) {
      const auto back = directed.find({e.second, e.first});
      if (n != 1 || (back != directed.end() && back->second != 1) || (complete && back == directed.end()))
        return "label rank " + std::to_string(L) + ": inner edge " + std::to_string(e.first) + "-" +
               std::to_string(e.second) + " is not used once each way";
    }
    std::vector<std::vector<int>> loops;
    for (const auto& [apex, link] : links)  // one cycle around each apex
      if (complete && (!cycles_of(link, loops) || loops.size() != 1))
        return "label rank " + std::to_string(L) + ": its triangles pinch at a fan's apex";
  }
  return {};
}

}  // namespace voxpress
