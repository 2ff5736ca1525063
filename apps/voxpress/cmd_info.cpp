// voxpress info FILE: lattice, voxel type, labels with counts, sticks.
#include <cmath>
#include <cstdio>
#include <optional>

#include "common.h"

namespace voxpress::cli {
namespace {

struct InfoCmd {
  std::string input, json;
  InputOptions in;
};

std::string fmt(double v) {
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}

void run_info(const InfoCmd& c, const Global& g) {
  check_paths({c.input}, {{c.json, OutputKind::json}});

  const ScalarVolume v = load_volume(c.input, c.in, g);
  const Lattice& L = v.lattice;
  nlohmann::json j;
  j["file"] = c.input;
  j["lattice"] = lattice_json(L);
  j["voxel_type"] = scalar_name(v.type);
  j["components"] = v.components;
  std::printf("file        %s\n", c.input.c_str());
  std::printf("dims        %ld x %ld x %ld (%lu samples)%s\n", long(L.dims[0]), long(L.dims[1]), long(L.dims[2]),
              (unsigned long)L.size(), v.components > 1 ? (" x " + std::to_string(v.components) + " layers").c_str() : "");
  std::printf("spacing     %s %s %s\n", fmt(L.spacing.x()).c_str(), fmt(L.spacing.y()).c_str(), fmt(L.spacing.z()).c_str());
  std::printf("origin      %s %s %s\n", fmt(L.origin.x()).c_str(), fmt(L.origin.y()).c_str(), fmt(L.origin.z()).c_str());
  for (int a = 0; a < 3; ++a)
    std::printf("%s %s %s %s\n", a == 0 ? "direction  " : "           ", fmt(L.direction(0, a)).c_str(),
                fmt(L.direction(1, a)).c_str(), fmt(L.direction(2, a)).c_str());
  std::printf("space       %s\n", space_name(L.space));
  std::printf("voxel type  %s\n", scalar_name(v.type));

  // Labels (or value range for grey volumes), with the sticks of each label.
  const auto hist = value_histogram(v, 4096);
  nlohmann::json labels = nlohmann::json::array();
  if (hist) {
    size_t nonzero = 0;
    for (auto& [value, n] : *hist) nonzero += value != 0;
    const bool per_label = nonzero <= 64 && v.components == 1;
    // Integer label maps: one pass gives every label's contacts, whose sums
    // are the labels' sticks (a pass per label otherwise).
    bool integers = true;
    for (auto& [value, n] : *hist) integers = integers && value == std::floor(value);
    std::optional<LabelTable> table;
    if (v.components == 1 && nonzero > 0 && integers) table = label_table(v);
    auto sticks_of = [&](double value) {
      uint64_t n = 0;
      if (table) {
        for (const LabelContact& t : table->contacts) n += (t.a == value || t.b == value) ? t.sticks : 0;
        return n;
      }
      Selection s;
      s.kind = Selection::Kind::label;
      s.value = value;
      return count_sticks(binarize(v, s));
    };
    std::printf("values      %zu distinct\n", hist->size());
    std::printf("  %-12s %14s %12s\n", "value", "samples", per_label ? "sticks" : "");
    for (auto& [value, n] : *hist) {
      nlohmann::json e = {{"value", value}, {"samples", n}};
      std::string sticks;
      if (per_label && value != 0) {
        const uint64_t ns = sticks_of(value);
        e["sticks"] = ns;
        sticks = std::to_string(ns);
      }
      labels.push_back(e);
      std::printf("  %-12s %14lu %12s\n", fmt(value).c_str(), (unsigned long)n, sticks.c_str());
    }
    // Which labels touch (lattice edges between them), for label maps.
    if (table && nonzero > 1) {
      nlohmann::json contacts = nlohmann::json::array();
      size_t between = 0;
      for (const LabelContact& t : table->contacts) between += t.a != 0;
      std::printf("contacts    %zu pairs of labels touch%s\n", between, between > 64 ? " (listed in --json)" : "");
      for (const LabelContact& t : table->contacts) {
        if (t.a == 0) continue;
        contacts.push_back({{"labels", {t.a, t.b}}, {"sticks", t.sticks}});
        if (between <= 64)
          std::printf("  %s-%s %*lu sticks\n", fmt(t.a).c_str(), fmt(t.b).c_str(), 20, (unsigned long)t.sticks);
      }
      j["contacts"] = contacts;
    }
  } else {
    double lo = v.value(0), hi = lo;
    for (uint64_t i = 0; i < v.value_count(); ++i) {
      const double x = v.value(i);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    std::printf("values      grey-level, %s .. %s (use --threshold T)\n", fmt(lo).c_str(), fmt(hi).c_str());
    j["range"] = {lo, hi};
  }
  j["labels"] = labels;
  if (!v.segments.empty()) {
    nlohmann::json segs = nlohmann::json::array();
    std::printf("segments    %zu\n", v.segments.size());
    for (const Segment& s : v.segments) {
      std::printf("  %-24s label %s, layer %ld (id %s)\n", s.name.c_str(), fmt(s.label).c_str(), long(s.layer),
                  s.id.c_str());
      segs.push_back({{"name", s.name}, {"id", s.id}, {"label", s.label}, {"layer", s.layer}});
    }
    j["segments"] = segs;
  }
  // Sticks of the selection the other commands would use, when it is unambiguous.
  try {
    const BinaryVolume b = binarize(v, c.in.selection());
    const uint64_t n = count_sticks(b);
    std::printf("sticks      %lu (inside samples: %lu)\n", (unsigned long)n, (unsigned long)b.count_inside());
    j["sticks"] = n;
    j["inside_samples"] = b.count_inside();
  } catch (const InputError& e) {
    std::printf("sticks      n/a: %s\n", e.problem().c_str());
  }
  if (!c.json.empty()) write_json(c.json, j);
}

}  // namespace

void register_info(CLI::App& app, Global& g) {
  auto c = std::make_shared<InfoCmd>();
  auto* cmd = app.add_subcommand("info", "Describe a volume: lattice, voxel type, labels, sticks");
  cmd->add_option("input", c->input, "Volume file (or folder of TIFF slices)")->required();
  c->in.bind(*cmd);
  cmd->add_option("--json", c->json, "Also write the description as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_info(*c, g);
  });
}

}  // namespace voxpress::cli
