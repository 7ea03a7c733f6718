// Demo step "capture" (docs/capture.md): the chain from a camera to a probe, measured against the lab's
// truth. The lab shoots a chrome ball in low-scene1 (without its projector) from two sides 90° apart, each side as five
// 8-bit JPEG exposures 2 EV apart (q95, shot and read noise, the sRGB curve); each bracket is merged with the curve
// recovered from it (Debevec & Malik); the two HDR balls are unwarped into one probe; the probe's
// irradiance is compared with the lab's exact probe at the ball's centre over 20480 normals. Pictures: the
// brackets, the recovered curve beside the true one, the two balls, the blend weights, the probe beside the
// truth. The errors and times go into summary.json under "capture".
#ifdef IBLKIT_HAVE_GEOMETRY
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/capture/ball.h"
#include "iblkit/capture/merge.h"
#include "iblkit/capture/probe_eval.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/photo.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/shoot.h"
#include "iblkit/lab/truth.h"
#include "iblkit/sphere/pointset.h"

namespace {

namespace fs = std::filesystem;
using ibl::Image;
using ibl::Vec3;

constexpr int kPhoto = 256;    // each view's photograph, pixels
constexpr int kProbe = 128;    // the probe's and the truth's lat-long height
constexpr int kFrames = 5;     // exposures per side
constexpr double kEvStep = 2;  // stops between them

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The recovered curve (green) over the true one (grey), exposure on a log axis against code value.
Image curve_picture(const ibl::capture::Response& truth, const ibl::capture::Response& recovered) {
  constexpr int kSize = 256;
  Image img(kSize, kSize, 3, 0.05f);
  const double lo = std::log2(1e-4);
  auto plot = [&](const ibl::capture::Response& r, Vec3 rgb, double scale) {
    double px = -1, py = -1;
    for (int i = 1; i <= 255; ++i) {
      const double z = i / 255.0, x = r.invert(z, 1) * scale;
      if (!(x > 0)) continue;
      const double u = (std::log2(x) - lo) / -lo * (kSize - 1), v = (1 - z) * (kSize - 1);
      if (px >= 0) ibl::io::draw_line(img, px, py, u, v, rgb, 2);
      px = u;
      py = v;
    }
  };
  // A recovered curve's scale is not observable from a bracket: it is drawn through the true curve at code 0.5.
  const double scale = truth.invert(0.5, 1) / std::max(recovered.invert(0.5, 1), 1e-30);
  plot(truth, {0.6, 0.6, 0.6}, 1);
  plot(recovered, {0.2, 0.9, 0.3}, scale);
  return img;
}

// low-scene1 without its projector. A ball photograph samples each pixel's rays; the projector's 3 cm aperture
// (and low-scene2's two small lamps) would be point-sampled by them, missed or doubled, while the lab's truth
// integrates them: the chain would be measured against light the camera cannot record at this resolution.
ibl::lab::Scene demo_scene() {
  ibl::lab::Scene s = ibl::lab::load_scene("low-scene1", false);
  s.emitters.erase(
      std::remove_if(s.emitters.begin(), s.emitters.end(),
                     [](const ibl::lab::Emitter& e) { return e.type == ibl::lab::EmitterType::Projector; }),
      s.emitters.end());
  return s;
}

void capture_step(iblcli::DemoContext& ctx) {
  auto t0 = std::chrono::steady_clock::now();
  const fs::path dir = fs::path(ctx.out_dir) / "capture";
  ibl::make_output_folders(dir.string());
  ibl::lab::Scene scene = demo_scene();
  ibl::lab::ShootDesc sd;
  sd.ball_center = {0, 1, 0};
  sd.distance = 2.0;  // 40 radii: the photographer's feet fall inside the other view's exclusion cone
  sd.width = sd.height = kPhoto;
  sd.views_deg = {0, 90};
  sd.render = scene.render;
  const auto shots = ibl::lab::shoot(scene, sd);
  const double shoot_s = seconds_since(t0);

  auto t1 = std::chrono::steady_clock::now();
  ibl::lab::BracketDesc bd;
  bd.sensor.f_number = 4;
  bd.sensor.full_well = 20000;
  bd.sensor.read_noise = 0.001;
  std::vector<ibl::capture::BallView> views;
  std::vector<std::pair<std::string, Image>> pictures;
  ibl::capture::Response recovered;
  nlohmann::json per_view = nlohmann::json::array();
  for (size_t v = 0; v < shots.size(); ++v) {
    // Centred 2 EV under middle grey: the room's lights are stops above the ball's median.
    bd.exposures_s = ibl::lab::bracket_times(
        kFrames, kEvStep, ibl::lab::middle_grey_exposure(shots[v].radiance, shots[v].ball, bd.sensor) / 4);
    bd.sensor.seed = 10 + v;
    const auto frames = ibl::lab::bracket(shots[v].radiance, bd);
    std::vector<ibl::capture::Frame> cf;
    for (size_t k = 0; k < frames.size(); ++k) {
      const std::string path = (dir / fmt::format("view{}_e{}.jpg", v, k)).string();
      ibl::io::PhotoMeta pm;
      pm.exposure_time = frames[k].exposure_s;
      pm.f_number = bd.sensor.f_number;
      pm.iso = bd.sensor.iso;
      ibl::io::write_photo(path, frames[k].codes, 8, pm, 95);
      const ibl::io::Photo p = ibl::io::read_photo(path);  // what a camera's files give
      const double iso = p.meta.iso > 0 ? p.meta.iso : 100;
      cf.push_back({p.codes, p.meta.exposure_time * (iso / 100) / (p.meta.f_number * p.meta.f_number), path});
      if (v == 0) pictures.push_back({fmt::format("view 0, {:.4g} s", frames[k].exposure_s), p.codes});
    }
    ibl::capture::MergeDesc md;  // the curve recovered from the bracket itself
    md.align = false;
    ibl::capture::MergeReport rep;
    const Image hdr = ibl::capture::merge_hdr(cf, md, &rep);
    if (v == 0) recovered = rep.response;
    ibl::io::write_image((dir / fmt::format("view{}.exr", v)).string(), hdr);
    views.push_back({hdr, shots[v].ball, shots[v].distance_radii, shots[v].angle_deg, fmt::format("view {}", v)});
    per_view.push_back({{"dynamic_range_stops", rep.dynamic_range_stops},
                        {"saturated_everywhere", rep.saturated_everywhere},
                        {"black_everywhere", rep.black_everywhere}});
  }
  const double merge_s = seconds_since(t1);

  auto t2 = std::chrono::steady_clock::now();
  ibl::capture::FromBallDesc fd;
  fd.size = kProbe;
  const auto probe = ibl::capture::probe_from_ball(views, fd);
  const double unwarp_s = seconds_since(t2);
  ibl::io::write_image((dir / "probe.exr").string(), probe.probe.image);

  ibl::lab::Scene truth_scene = demo_scene();
  truth_scene.build();
  ibl::lab::TruthDesc td;
  td.size = kProbe;
  td.bands = 0;
  const ibl::lab::Truth truth = ibl::lab::ground_truth(truth_scene, sd.ball_center, td);
  ibl::io::write_image((dir / "truth.exr").string(), truth.radiance.image);
  const auto normals = ibl::sphere::fibonacci_sphere(20480);
  const double err = ibl::capture::mean_relative_luminance_error(
      ibl::capture::probe_irradiance(probe.probe, normals), ibl::capture::probe_irradiance(truth.radiance, normals));

  // Pictures: view 0's bracket, the curve, the two balls, the weights, the probe beside the truth.
  pictures.push_back({"recovered curve (green) / sRGB (grey)", curve_picture(bd.sensor.response, recovered)});
  for (const auto& v : views) pictures.push_back({v.name + " merged", ibl::io::tonemap(v.photo)});
  Image weights(probe.weights.width(), probe.weights.height(), 3);
  for (int y = 0; y < weights.height(); ++y)
    for (int x = 0; x < weights.width(); ++x) {
      const float w = probe.weights.at(x, y, 0);
      weights.set_rgb(x, y, {w, w, w});
    }
  pictures.push_back({"blend weights (view 0's share)", weights});
  ibl::io::ToneMapDesc tm;
  tm.auto_exposure = false;
  tm.exposure_stops = std::log2(ibl::io::auto_exposure_scale(truth.radiance.image));
  pictures.push_back({"probe from the ball", ibl::io::tonemap(probe.probe.image.with_channels(3), tm)});
  pictures.push_back({"truth (the lab's probe)", ibl::io::tonemap(truth.radiance.image, tm)});
  const std::string png = (dir / "capture.png").string();
  ibl::io::write_image(png, ibl::io::contact_sheet(pictures, 5, 256, 160));
  ctx.pictures.push_back({"capture: brackets -> hdr merge -> probe from-ball vs the lab's probe", png});
  ctx.summary["capture"] = {{"scene", "low-scene1 without its projector"},
                            {"views", shots.size()},
                            {"frames_per_view", kFrames},
                            {"ev_step", kEvStep},
                            {"jpeg_quality", 95},
                            {"irradiance_error_mean_relative", err},
                            {"normals", normals.size()},
                            {"merge", per_view},
                            {"invalid_probe_pixels", probe.invalid_pixels},
                            {"seconds", {{"shoot", shoot_s}, {"merge", merge_s}, {"unwarp", unwarp_s}}}};
  iblcli::info(
      fmt::format("capture: two JPEG brackets merged and unwarped: irradiance {:.2f} % from the lab's probe "
                  "(shoot {:.1f} s, merge {:.1f} s, unwarp {:.1f} s)",
                  100 * err, shoot_s, merge_s, unwarp_s));
}

iblcli::DemoStep step("capture", 90, capture_step);

}  // namespace
#endif  // IBLKIT_HAVE_GEOMETRY
