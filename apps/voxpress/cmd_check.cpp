// voxpress check MESH [--volume VOL]: mesh validity and the in/out guarantee.
#include <cstdio>

#include "common.h"

namespace voxpress::cli {
namespace {

struct CheckCmd {
  std::string mesh, volume, json;
  InputOptions in;
  bool no_self_intersections = false, parity = false;
};

void run_check(const CheckCmd& c, const Global& g) {
  check_paths({c.mesh, c.volume}, {{c.json, OutputKind::json}});

  const Mesh mesh = read_mesh(c.mesh, {g.memory_limit()});
  MeshCheckOptions mo;
  mo.self_intersections = !c.no_self_intersections;
  const MeshCheck r = check_mesh(mesh, mo);
  nlohmann::json j;
  j["mesh"] = c.mesh;
  j["vertices"] = r.vertices;
  j["faces"] = r.faces;
  j["closed"] = r.closed();
  j["manifold"] = r.manifold();
  j["oriented"] = r.oriented();
  j["components"] = r.components;
  j["euler_characteristic"] = r.euler;
  j["signed_volume"] = r.signed_volume;
  j["area"] = r.area;
  j["self_intersections"] = r.self_intersections_checked ? nlohmann::json(r.self_intersections) : nlohmann::json();
  j["problems"] = r.problems;
  std::printf("mesh        %s: %zu vertices, %zu faces, %zu components, Euler characteristic %ld\n", c.mesh.c_str(),
              r.vertices, r.faces, r.components, long(r.euler));
  std::printf("closed %s, manifold %s, oriented %s, self-intersections %s, volume %g, area %g\n",
              r.closed() ? "yes" : "NO", r.manifold() ? "yes" : "NO", r.oriented() ? "yes" : "NO",
              r.self_intersections_checked ? std::to_string(r.self_intersections).c_str() : "not checked",
              r.signed_volume, r.area);
  for (const auto& p : r.problems) std::printf("problem     %s\n", p.c_str());
  bool ok = r.ok();
  if (!c.volume.empty()) {
    const BinaryVolume vol = load_binary(c.volume, c.in, g);
    ProgressBar bar(!g.quiet);
    ClassificationOptions co;
    co.progress = bar.get();
    co.rule = c.parity ? ClassificationOptions::Rule::parity : ClassificationOptions::Rule::winding;
    const ClassificationReport cr = check_classification(mesh, vol, co);
    std::printf("samples     %lu checked against %s: %lu violations (%lu inside found outside, %lu outside found "
                "inside, %lu on the surface)\n",
                (unsigned long)cr.samples, c.volume.c_str(), (unsigned long)cr.violations,
                (unsigned long)cr.inside_found_outside, (unsigned long)cr.outside_found_inside,
                (unsigned long)cr.on_surface);
    for (const auto& e : cr.examples) std::printf("  violation at sample (%ld, %ld, %ld)\n", long(e[0]), long(e[1]), long(e[2]));
    j["classification"] = {{"samples", cr.samples},
                           {"violations", cr.violations},
                           {"inside_found_outside", cr.inside_found_outside},
                           {"outside_found_inside", cr.outside_found_inside},
                           {"on_surface", cr.on_surface}};
    ok = ok && cr.violations == 0;
  }
  j["ok"] = ok;
  if (!c.json.empty()) write_json(c.json, j);
  std::printf("verdict     %s\n", ok ? "OK" : "FAILED");
  OutputGroup::commit_open();  // the report of a failed check is delivered
  if (!ok) throw InputError(c.mesh, "the mesh failed its checks");
}

}  // namespace

void register_check(CLI::App& app, Global& g) {
  auto c = std::make_shared<CheckCmd>();
  auto* cmd = app.add_subcommand("check", "Check a mesh: closed, manifold, oriented, no self-intersections; "
                                          "with --volume, every sample on its own side");
  cmd->add_option("mesh", c->mesh, "Mesh file (.ply .obj .stl .off)")->required();
  cmd->add_option("--volume", c->volume, "Volume whose samples the mesh must separate");
  c->in.bind(*cmd);
  cmd->add_flag("--no-self-intersections", c->no_self_intersections, "Skip the self-intersection test");
  cmd->add_flag("--parity", c->parity, "Classify by ray parity instead of winding number (orientation-blind)");
  cmd->add_option("--json", c->json, "Also write the report as JSON");
  cmd->callback([c, &g] {
    g.apply();
    run_check(*c, g);
  });
}

}  // namespace voxpress::cli
