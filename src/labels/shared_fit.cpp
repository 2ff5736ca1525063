// The local quadric fit on a shared surface: each label's binary fit on the
// cubes it owns, checked cube by cube. Theory of operation:
// include/voxpress/labels/shared_fit.h.
#include "voxpress/labels/shared_fit.h"


#include <algorithm>
#include <chrono>

#include "core/clearance.h"
#include "core/timing.h"
#include "cube_check.h"
#include "label_view.h"
#include "core/parallel.h"
#include "features/feature_context.h"

namespace voxpress {

SharedFitStats fit_shared_quadrics(SharedSurface& s, const LabelMasks& masks, const std::vector<LabelInfo>& labels,
                                   const SharedFlats* flats, const QuadricFitOptions& options, const PassSet& passes) {
  const auto t0 = std::chrono::steady_clock::now();
  SharedFitStats st;
  // Nothing to fit: no rings, or the table's driver would run no fit step.
  if (options.rings <= 0 || !runs(feature_passes()[size_t(Pass::quadric_fit)], passes)) return st;
  // Every label of `labels` takes part (by its index in s.labels).
  const std::vector<size_t> info_of = detail::listed_labels(s, labels);
  std::vector<uint8_t> takes_part(s.labels.size(), 0);
  for (size_t l = 0; l < s.labels.size(); ++l) takes_part[l] = info_of[l] != SIZE_MAX;
  const detail::Ownership own = detail::ownership(s, takes_part);
  const detail::SharedSticks sticks(s);
  std::vector<uint32_t> todo;
  for (uint32_t l = 0; l < s.labels.size(); ++l)
    if (!own.mine[l].empty()) todo.push_back(l);
  struct Fit {
    std::vector<std::pair<uint32_t, Vec3>> moved;  // shared vertex, index-space position
    size_t cubes = 0, fitted = 0;
    PassTimes times;
  };
  std::vector<Fit> fits(todo.size());
  const FlatSegmentation no_flats;
  detail::parallel_for(todo.size(), [&](size_t i) {
    const uint32_t l = todo[i];
    const LabelInfo& info = labels[info_of[l]];
    detail::LabelView v = detail::label_view(s, own, sticks, masks(info), detail::mask_origin(info.lo), l);
    Fit& f = fits[i];
    f.cubes = v.cubes;
    if (v.cubes == 0) return;
    const FlatSegmentation* seg = flats && info_of[l] < flats->segmentations.size() &&
                                          !flats->segmentations[info_of[l]].flats.empty()
                                      ? &flats->segmentations[info_of[l]]
                                      : nullptr;
    const std::vector<double> before = v.surf.t;
    std::vector<uint8_t> only(v.fixed.size());
    for (size_t k = 0; k < only.size(); ++k) only[k] = !v.fixed[k];
    // The binary pipeline's fit stage on the label's view (one driver, one pass table).
    const detail::Adjacency graph(v.surf.stick_count(), v.surf.triangles);
    detail::FitStage fit{v.surf, seg ? *seg : no_flats, graph, options, {}, &only};
    detail::FeatureContext fc{passes, f.times};
    fc.fit = &fit;
    detail::run_stage(Stage::fit, fc);
    f.fitted = fit.out.fitted;
    for (size_t k = 0; k < v.surf.stick_count(); ++k)
      if (!v.fixed[k] && v.surf.t[k] != before[k]) f.moved.push_back({v.idx[k], v.shared_position(k)});
  });
  // Applied, then every cube with a moved vertex checked exactly.
  const size_t n = s.mesh.positions.size();
  std::vector<Vec3> x(n), x0(n);
  detail::parallel_for(n, [&](size_t v) {
    x[v] = s.lattice.to_index(s.mesh.positions[v]);
    x0[v] = detail::element_centre(s, v);
  });
  const std::vector<Vec3> back = x;
  std::vector<uint8_t> reset(n, 1);  // put_back moves only the vertices the fit moved
  for (const Fit& f : fits) {
    st.passes.add(f.times);
    st.labels += f.cubes > 0;
    st.cubes += f.cubes;
    st.fitted += f.fitted;
    for (const auto& [v, p] : f.moved) {
      x[v] = p;
      reset[v] = 0;
    }
  }
  std::vector<uint8_t> moved(n);
  for (size_t v = 0; v < n; ++v) moved[v] = !reset[v];
  const detail::Cubes cubes = detail::cubes_of(s.mesh, x0, &moved);  // put_back visits moved vertices only
  std::vector<uint32_t> touched;
  for (uint32_t v = 0; v < n; ++v)
    if (!reset[v])
      touched.insert(touched.end(), cubes.vertex_groups.begin() + cubes.vertex_offsets[v],
                     cubes.vertex_groups.begin() + cubes.vertex_offsets[v + 1]);
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  const double delta = detail::float32_clearance_around(s.lattice, x);
  st.cubes_put_back = detail::put_back(s.mesh, cubes, detail::failing_cubes(s.mesh, cubes, touched, x, delta), x,
                                       back, reset, delta);
  detail::parallel_for(n, [&](size_t v) {
    if (!reset[v]) s.mesh.positions[v] = s.lattice.to_physical(x[v]);  // the others keep their bits
  });
  for (uint32_t v = 0; v < n; ++v) st.moved += !reset[v];
  s.mesh.normals.clear();
  st.seconds = detail::seconds_since(t0);
  return st;
}

}  // namespace voxpress
