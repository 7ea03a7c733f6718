#include "iblkit/nearfield/scene_render.h"

#include <chrono>

#include "iblkit/core/error.h"
#include "iblkit/nearfield/ies.h"
#include "iblkit/nearfield/reconstruct.h"
#include "iblkit/nearfield/spotlight.h"

namespace ibl::nearfield {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::optional<Luminaire> exact_luminaire(const Dataset& ds, const std::string& name) {
  if (name.empty() || name == "none") return std::nullopt;
  const std::string lum = name == "auto" ? ds.luminaire : name;
  if (lum.empty())
    fail(ErrorKind::Value, "exact luminaire 'auto': the dataset names no lab luminaire (a measured dataset)");
  return make_luminaire(lum);
}

SceneRender render_scene(const SceneView& sv, const SceneRenderDesc& d, const ProgressFn& progress) {
  if (d.dataset.empty() == d.ies.empty())
    fail(ErrorKind::Value, "scene render: give a dataset or an IES file (one of them)");
  const Placement& pl = d.placement;
  pl.frame();  // validates
  SceneRender r;
  std::vector<TexturedSpotlight> lights;
  Dataset ds;
  auto t0 = std::chrono::steady_clock::now();
  if (!d.ies.empty()) {
    lights.push_back(ies_spotlight(read_ies(d.ies), pl, 80, 256, d.ies_scale));
    r.label = d.ies;
  } else {
    ds = read_dataset(d.dataset);
    lights = spotlights(ds, pl, d.shadows);
    r.label = ds.name;
  }
  r.setup_seconds = seconds_since(t0);
  r.spotlights = lights.size();
  t0 = std::chrono::steady_clock::now();
  r.near_field = render_spotlights(sv, lights, d.camera, d.shadows, progress);
  r.render_seconds = seconds_since(t0);
  if (d.srgbe) {
    // The paper's 8-bit sRGBE frame buffer between passes of 3 spotlights, against the float sum.
    const Image q = render_spotlights(sv, lights, d.camera, d.shadows, {}, 3);
    r.srgbe_error = compare(q, r.near_field);
    r.srgbe_passes = (lights.size() + 2) / 3;
  }
  const auto lum = d.ies.empty() ? exact_luminaire(ds, d.exact) : std::nullopt;
  if (!lum) return r;
  t0 = std::chrono::steady_clock::now();
  r.exact = render_exact(sv, *lum, pl, d.camera, d.shadows);
  r.exact_seconds = seconds_since(t0);
  r.near_field_error = compare(r.near_field, *r.exact);
  if (d.far_field) {
    const auto ff = far_field_spotlight([&](Vec3 w) { return lum->intensity(w); }, ds.distance, ds.m_max.x,
                                        ds.positive[0].width(), pl, d.shadows);
    r.far_field = render_spotlights(sv, {ff}, d.camera, d.shadows);
    r.far_field_error = compare(*r.far_field, *r.exact);
  }
  return r;
}

}  // namespace ibl::nearfield
