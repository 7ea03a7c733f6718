// Demo step "composite" (docs/augment.md): the blob composited into a lab photograph of low-scene2 at two
// places, each beside the lab's truth (photograph | composite | truth | 4 × |composite − truth|), and into the
// demo's real probe: the probe seen from where it was taken is the photograph, a floor under it the proxy.
// The errors and times go into summary.json under "composite".
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/augment/composite.h"
#include "iblkit/augment/load.h"
#include "iblkit/augment/measure.h"
#include "iblkit/augment/run_composite.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
#include "iblkit/lab/view.h"
#include "iblkit/render/objects.h"

namespace {

namespace fs = std::filesystem;
using ibl::Image;
using ibl::Vec3;

constexpr int kWidth = 160, kHeight = 120;  // small frames: the step takes seconds
constexpr int kTruthSamples = 8;            // 8×8 rays per pixel of each lab photograph
constexpr int kDiffGain = 4;                // the difference panel shows 4 × |composite − truth|

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A tone-mapped strip of panels, all with the exposure of the first (the photograph).
Image strip(const std::vector<std::pair<std::string, Image>>& hdr) {
  ibl::io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(ibl::io::auto_exposure_scale(hdr.front().second));
  std::vector<std::pair<std::string, Image>> ldr;
  for (const auto& [caption, img] : hdr) ldr.push_back({caption, ibl::io::tonemap(img, td)});
  return ibl::io::contact_sheet(ldr, static_cast<int>(ldr.size()), kWidth * 2, kHeight * 2);
}

Image abs_difference(const Image& a, const Image& b, double gain) {
  Image d(a.width(), a.height(), 3);
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      Vec3 v = a.rgb(x, y) - b.rgb(x, y);
      d.set_rgb(x, y, Vec3{std::abs(v.x), std::abs(v.y), std::abs(v.z)} * gain);
    }
  return d;
}

ibl::lab::View photograph(const ibl::lab::Scene& scene, const ibl::geometry::Camera& cam, int bounces) {
  ibl::lab::ViewDesc vd;
  vd.width = cam.width;
  vd.height = cam.height;
  vd.samples = kTruthSamples;
  vd.render = scene.render;
  vd.render.bounces = bounces;
  return ibl::lab::photograph(
      scene,
      [&](double px, double py, Vec3* o, Vec3* d) {
        *o = cam.eye;
        *d = cam.ray_direction(px, py);
      },
      vd);
}

// low-scene2 with the blob at `at`: photograph, truth, one probe at the object, composite, errors.
nlohmann::json lab_case(iblcli::DemoContext& ctx, const fs::path& dir, const ibl::geometry::Camera& cam,
                        const Image& photo, Vec3 at, const std::string& name) {
  auto t0 = std::chrono::steady_clock::now();
  ibl::augment::CompositeJob job;
  job.object.at = at;
  const ibl::geometry::TriMesh object = ibl::render::make_object(job.object);
  ibl::lab::Scene with = ibl::lab::load_scene("low-scene2", false);
  ibl::lab::add_object(with, "object", object, job.material.albedo);
  with.build();
  const Image truth = photograph(with, cam, 2).radiance;  // the probes carry one bounce: the photograph reflects it
  const double truth_s = seconds_since(t0);
  ibl::lab::Scene scene = ibl::lab::load_scene("low-scene2");
  ibl::lab::SequenceDesc sd;
  sd.capture.render = scene.render;
  sd.capture.render.bounces = 1;
  sd.capture.size = 128;
  sd.capture.depth = true;
  sd.capture.samples = 4;  // 4×4 rays per texel: a camera pixel integrates (one ray misses or doubles small lamps)
  sd.out_dir = (dir / (name + "_probe")).string();
  ibl::lab::write_probe_set(scene, {at}, sd);
  job.light.probes = (fs::path(sd.out_dir) / "probes.json").string();
  job.match = ibl::augment::Match::Off;  // the lab's probe and photograph are one unit (its probe: one bounce fewer)
  const ibl::augment::CompositeResult r = ibl::augment::run_composite(photo, cam, job).result;
  ibl::augment::CompositeErrors e = ibl::augment::measure(photo, r.composite, truth, r.mask);
  std::string png = (dir / (name + ".png")).string();
  ibl::io::write_image(
      png,
      strip({{"photograph", photo},
             {"composite (one probe)", r.composite},
             {"truth (lab, object in it)", truth},
             {fmt::format("{} x |composite - truth|", kDiffGain), abs_difference(r.composite, truth, kDiffGain)}}));
  ctx.pictures.push_back({fmt::format("composite: low-scene2, blob at ({:g}, {:g}, {:g})", at.x, at.y, at.z), png});
  return {{"at", {at.x, at.y, at.z}},
          {"object_error", e.object},
          {"shadow_error", e.shadow},
          {"unchanged_error", e.unchanged},
          {"object_pixels", e.object_pixels},
          {"shadow_pixels", e.shadow_pixels},
          {"composite_seconds", r.stats.seconds},
          {"truth_seconds", truth_s}};
}

// The demo's real probe with a floor under it: the photograph is the probe seen from its own centre (so the
// floor it shows is where the proxy is), the blob stands on the floor in front.
nlohmann::json real_case(iblcli::DemoContext& ctx, const fs::path& dir) {
  constexpr double kProbeHeight = 1.2;  // metres: the probe above its floor (the file does not say; a tripod's height)
  ibl::sphere::EnvMap env = ibl::io::read_envmap(ctx.probe);
  ibl::sphere::Mapping ll(ibl::sphere::MappingKind::LatLong, 256, 128);
  ibl::augment::LocalRadiance light;
  light.map = ibl::sphere::EnvMap(ibl::sphere::resample(env, ll), ll);
  light.centre = {0, kProbeHeight, 0};
  light.source = "probe " + fs::path(ctx.probe).filename().string();
  ibl::geometry::TriMesh floor = ibl::geometry::make_floor(40, 0);
  ibl::geometry::Camera cam;
  cam.eye = light.centre;
  cam.target = {0, 0.15, -1.5};
  cam.fov_y_deg = 50;
  cam.width = kWidth;
  cam.height = kHeight;
  Image photo(kWidth, kHeight, 3);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) photo.set_rgb(x, y, light.map.sample_rgb(cam.ray_direction(x + 0.5, y + 0.5)));
  ibl::render::ObjectDesc od = ibl::augment::inserted_object_defaults();
  od.at = {0, 0.2, -1.5};
  od.size = 0.4;
  ibl::geometry::TriMesh object = ibl::render::make_object(od);
  Vec3 lo, hi;
  object.bounds(&lo, &hi);
  object.transform(1.0, {0, 0.002 - lo.y, 0});  // standing on the floor, 2 mm above it
  ibl::augment::CompositeResult r =
      ibl::augment::composite(photo, cam, floor, light, object, ibl::augment::CompositeJob{}.material);
  std::string png = (dir / "real_probe.png").string();
  ibl::io::write_image(
      png, strip({{"probe seen from its centre", photo},
                  {"composite (floor proxy)", r.composite},
                  {fmt::format("{} x |difference|", kDiffGain), abs_difference(r.composite, photo, kDiffGain)}}));
  ctx.pictures.push_back({"composite: blob on a floor under " + fs::path(ctx.probe).filename().string(), png});
  return {{"probe", ctx.probe},
          {"probe_height_m", kProbeHeight},
          {"object_pixels", r.stats.object_pixels},
          {"changed_pixels", r.stats.changed_pixels},
          {"albedo_over_one", r.stats.albedo_over_one},
          {"composite_seconds", r.stats.seconds},
          {"warnings", r.warnings}};
}

void composite_step(iblcli::DemoContext& ctx) {
  fs::path dir = fs::path(ctx.out_dir) / "composite";
  fs::create_directories(dir);
  ibl::geometry::Camera cam;
  cam.eye = {0, 1.3, 2.2};
  cam.target = {0, 0.3, 0};
  cam.fov_y_deg = 40;
  cam.width = kWidth;
  cam.height = kHeight;
  const Image photo = photograph(ibl::lab::load_scene("low-scene2"), cam, 2).radiance;
  nlohmann::json j;
  j["low-scene2"] = {lab_case(ctx, dir, cam, photo, {0.1, 0.2, 0.1}, "low-scene2_a"),
                     lab_case(ctx, dir, cam, photo, {-0.45, 0.2, 0.35}, "low-scene2_b")};
  j["real_probe"] = real_case(ctx, dir);
  j["frame"] = {kWidth, kHeight};
  j["truth_rays_per_pixel"] = kTruthSamples * kTruthSamples;
  ctx.summary["composite"] = j;
}

iblcli::DemoStep step("composite", 85, composite_step);

}  // namespace
#endif  // IBLKIT_HAVE_GEOMETRY
