// iblkit composite PHOTO …: a virtual object inserted into a photograph with its shading, occlusion,
// shadows and interreflection (differential rendering, augment/composite.h; docs/augment.md).
#ifdef IBLKIT_HAVE_GEOMETRY
#include <cctype>
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli.h"
#include "iblkit/augment/capture_chain.h"
#include "iblkit/augment/composite.h"
#include "iblkit/augment/measure.h"
#include "iblkit/augment/overlay.h"
#include "iblkit/augment/run_composite.h"
#include "iblkit/capture/backplate.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/io/dng.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "render_setup.h"

namespace {

namespace fs = std::filesystem;
using ibl::Vec3;

// The light's turn registered from the proxy both see (--register).
nlohmann::json registration_json(const ibl::augment::CompositeRun& run) {
  const ibl::augment::YawFit& f = run.yaw;
  nlohmann::json j = {{"yaw_deg", f.yaw_deg},
                      {"spread_stops", f.spread},
                      {"spread_given_stops", f.spread_given},
                      {"runner_up_deg", f.runner_up_deg},
                      {"runner_up_spread_stops", f.runner_up_spread},
                      {"points", f.points},
                      {"valid", f.valid},
                      {"applied", run.turned}};
  const ibl::augment::PositionFit& p = run.position;
  if (p.points > 0)
    j["position"] = {{"offset_m", {p.offset.x, p.offset.y, p.offset.z}},
                     {"spread_stops", p.spread},
                     {"spread_given_stops", p.spread_given},
                     {"points", p.points},
                     {"valid", p.valid},
                     {"applied", run.moved}};
  return j;
}

struct Opts {
  std::string photo, probe_depth, object, at, albedo = "0.7,0.7,0.7", out = "composite.exr", layers, backend = "cpu",
                                              response, match = "auto", grey_card, capture;
  int quality = 0;
  bool recover_response = false;
  iblcli::PhotoSceneOptions scene;
  std::vector<std::string> light, truth;
  std::string lobe = "phong", texture, reg = "off";
  double gloss = 0, exponent = 20;
  ibl::augment::CompositeJob job;  // its object's and sampling's defaults are the library's
  Opts() {
    const ibl::Vec3 p = job.object.at;
    object = job.object.scene;
    at = fmt::format("{},{},{}", p.x, p.y, p.z);
  }
};

void write_layer(const fs::path& dir, const std::string& name, const ibl::Image& img) {
  ibl::io::write_image((dir / (name + ".exr")).string(), img);
}

nlohmann::json errors_json(const ibl::augment::CompositeErrors& e) {
  return {{"object", e.object},
          {"shadow", e.shadow},
          {"unchanged", e.unchanged},
          {"object_pixels", e.object_pixels},
          {"shadow_pixels", e.shadow_pixels},
          {"unchanged_pixels", e.unchanged_pixels},
          {"brightened_pixels", e.brightened_pixels},
          {"shadow_signal", e.shadow_signal}};
}

nlohmann::json vec_json(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

// The bit depth a photograph output gets: 8 for JPEG, else the backplate's own.
int output_bits(const std::string& out, const ibl::capture::Backplate& plate) {
  std::string ext = fs::path(out).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".jpg" || ext == ".jpeg" ? 8 : plate.photo.bits;
}

// Before any work: a raw output is not written (no raw writer; the composite of a raw backplate is a 16-bit linear
// TIFF, an 8-bit sRGB JPEG or an EXR).
void refuse_raw_output(const std::string& out) {
  if (ibl::io::is_raw_path(out))
    ibl::fail(ibl::ErrorKind::Value,
              "{}: iblkit writes no raw files: write the composite as .tif (16-bit, linear like the raw), .jpg (sRGB) "
              "or .exr",
              out);
}

void run(const Opts& o, const ibl::io::EnvReadDesc& read) {
  refuse_raw_output(o.out);
  if (o.light.size() > 1) ibl::fail(ibl::ErrorKind::Value, "--light: give one light file");
  ibl::augment::CompositeJob job = o.job;
  job.backend = ibl::augment::parse_backend(o.backend);
  const ibl::capture::Backplate plate = ibl::capture::read_backplate(o.photo, o.response);
  const ibl::Image& photo = plate.linear;
  const ibl::geometry::Camera cam = iblcli::photo_camera(o.scene, photo, o.photo, "");
  const ibl::Vec3 at = iblcli::parse_vec3(o.at, "--at");
  job.object.scene = o.object;
  job.object.at = at;
  job.light = iblcli::photo_light_input(o.scene, o.light);
  job.light.probe_depth = o.probe_depth;
  job.light.read = read;
  job.material = iblcli::object_material(o.albedo, o.gloss, o.exponent, o.lobe, o.texture);
  job.match = o.match == "off" ? ibl::augment::Match::Off : ibl::augment::Match::Auto;
  job.reg = ibl::augment::parse_register(o.reg);
  if (!o.grey_card.empty()) {  // the card's rectangle: the match from its pixels alone
    int v[4];
    char tail = 0;
    if (std::sscanf(o.grey_card.c_str(), "%d,%d,%d,%d%c", &v[0], &v[1], &v[2], &v[3], &tail) != 4)
      ibl::fail(ibl::ErrorKind::Value, "--grey-card {}: expected x,y,w,h in pixels", o.grey_card);
    job.grey_card = {v[0], v[1], v[2], v[3]};
    job.match = ibl::augment::Match::GreyCard;
  } else if (o.match == "grey-card") {
    ibl::fail(ibl::ErrorKind::Value, "--match grey-card: give the card's pixels with --grey-card x,y,w,h");
  }
  if (plate.encoded) {  // the photograph's top code, linear: saturated pixels say nothing of the light's scale
    job.saturated = 1e30;
    for (int c = 0; c < 3; ++c) job.saturated = std::min(job.saturated, plate.response.invert(1.0, c) * (1 - 1e-6));
  }
  job.desc.progress = iblcli::progress_bar();
  const ibl::augment::CompositeRun run = ibl::augment::run_composite(photo, cam, job);
  iblcli::progress_done();
  for (const auto& n : run.notes) iblcli::info(n);
  const ibl::augment::CompositeResult& r = run.result;
  const std::string backend = ibl::augment::backend_name(run.backend);
  for (const auto& w : r.warnings) iblcli::info("warning: " + w);
  ibl::capture::BackplateReport br;
  const bool photo_out = plate.encoded && ibl::capture::is_photo_extension(o.out);
  if (photo_out) {  // back through the photograph's response, in its bit depth, with its metadata
    const int bits = output_bits(o.out, plate);
    const ibl::Image codes = ibl::capture::encode_like(plate, r.composite, bits, &br);
    ibl::capture::write_like(o.out, plate, codes, bits, o.quality);
    if (br.saturated_darkened > 0)
      iblcli::info(fmt::format(
          "warning: {} saturated pixels of {} lie under the object's shadow: their light is at least what they show, "
          "so the shadow there is a bound, too bright where the scene was brighter",
          br.saturated_darkened, o.photo));
  } else if (fs::path(o.out).extension() == ".png") {
    ibl::io::write_image(o.out, ibl::io::tonemap(r.composite));
  } else {
    ibl::io::write_image(o.out, r.composite);
  }
  if (!o.layers.empty()) {
    ibl::make_output_folders(fs::path(o.layers).string());
    fs::path dir(o.layers);
    write_layer(dir, "mask", r.mask);
    write_layer(dir, "difference", r.difference);
    write_layer(dir, "albedo", r.albedo);
    write_layer(dir, "render_with", r.render_with);
    write_layer(dir, "render_without", r.render_without);
    // The proxy's edges over the photograph, through the camera: does the camera agree with the proxy?
    ibl::io::write_image((dir / "proxy_overlay.png").string(),
                         ibl::augment::proxy_overlay(ibl::io::tonemap(photo), cam, run.proxy));
  }
  const auto& s = r.stats;
  nlohmann::json j = {{"out", o.out},
                      {"light", run.light_source},
                      {"backend", backend},
                      {"seconds", s.seconds},
                      {"proxy_pixels", s.proxy_pixels},
                      {"object_pixels", s.object_pixels},
                      {"changed_pixels", s.changed_pixels},
                      {"albedo_over_one", s.albedo_over_one},
                      {"unlit_pixels", s.unlit},
                      {"warnings", r.warnings}};
  if (!o.layers.empty()) j["layers"] = o.layers;
  if (run.match.points > 0 || run.matched)
    j["match"] = {{"gain", {run.match.gain.x, run.match.gain.y, run.match.gain.z}},
                  {"stops", std::log2(ibl::luminance(run.match.gain))},
                  {"points", run.match.points},
                  {"spread_stops", run.match.spread},
                  {"applied", run.matched}};
  if (run.yaw.points > 0 || run.position.points > 0) j["registration"] = registration_json(run);
  if (plate.encoded)
    j["backplate"] = {{"bits", plate.photo.bits},
                      {"response", plate.response.kind},
                      {"jpeg_quality", plate.photo.meta.jpeg_quality},
                      {"saturated_pixels", br.saturated},
                      {"saturated_changed", br.saturated_changed},
                      {"saturated_darkened", br.saturated_darkened},
                      {"kept_pixels", br.kept},
                      {"encoded_pixels", br.encoded}};
  ibl::augment::CompositeErrors e, noise;
  if (!o.truth.empty()) {
    std::vector<ibl::Image> truths;
    for (const auto& t : o.truth) truths.push_back(ibl::io::read_image(t));
    ibl::augment::TruthErrors te = ibl::augment::measure_against(photo, r.composite, truths, r.mask);
    e = te.errors;
    noise = te.noise;
    if (!o.layers.empty()) write_layer(o.layers, "truth_error", ibl::augment::error_picture(r.composite, te.mean));
    j["errors"] = errors_json(e);
    if (o.truth.size() > 1)
      j["truth_noise"] = {{"object", noise.object},
                          {"shadow", noise.shadow},
                          {"unchanged", noise.unchanged},
                          {"truths", o.truth.size()}};
  }
  iblcli::emit(j, [&] {
    fmt::print("composited the object into {} ({}x{}, light: {}, backend {}) in {:.2f} s: {}\n", o.photo, cam.width,
               cam.height, run.light_source, backend, s.seconds, o.out);
    fmt::print("  {} object pixels, {} proxy pixels changed by its shadow and light\n", s.object_pixels,
               s.changed_pixels);
    if (!o.layers.empty())
      fmt::print("  layers: {}/mask, difference, albedo, render_with, render_without (.exr), proxy_overlay.png\n",
                 o.layers);
    if (!o.truth.empty())
      fmt::print(
          "  against {}: object {:.1f} % ({} px), shadow {:.1f} % of the shadow signal ({} px, {:.0f} % darker), "
          "unchanged {:.2f} % ({} px)\n",
          fmt::join(o.truth, " + "), 100 * e.object, e.object_pixels, 100 * e.shadow, e.shadow_pixels,
          100 * e.shadow_signal, 100 * e.unchanged, e.unchanged_pixels);
    if (o.truth.size() > 1)
      fmt::print(
          "  the truths' mean's own noise (from their spread): object {:.1f} %, shadow {:.1f} %, unchanged {:.2f} %\n",
          100 * noise.object, 100 * noise.shadow, 100 * noise.unchanged);
  });
}

// composite --capture DIR: the chain from a capture folder (augment/capture_chain.h), and with the lab's truth in
// the folder, its errors.
void run_capture(const Opts& o) {
  refuse_raw_output(o.out);
  ibl::augment::ChainDesc cd;
  cd.job = o.job;
  cd.job.backend = ibl::augment::parse_backend(o.backend);
  cd.job.match = o.match == "off" ? ibl::augment::Match::Off : ibl::augment::Match::Auto;
  cd.job.reg = ibl::augment::parse_register(o.reg);
  if (o.match == "grey-card" || !o.grey_card.empty())
    ibl::fail(ibl::ErrorKind::Value, "--capture: the match is from the proxy (--match auto) or off");
  cd.job.material = iblcli::object_material(o.albedo, o.gloss, o.exponent, o.lobe, o.texture);
  cd.job.desc.progress = iblcli::progress_bar();
  cd.recover_response = o.recover_response;
  const ibl::capture::CaptureFolder folder = ibl::capture::read_capture(o.capture);
  const ibl::augment::ChainResult c = ibl::augment::run_capture(folder, cd);
  iblcli::progress_done();
  for (const auto& n : c.run.notes) iblcli::info(n);
  for (const auto& w : c.run.result.warnings) iblcli::info("warning: " + w);
  const ibl::augment::CompositeResult& r = c.run.result;
  const ibl::geometry::Camera& cam = c.camera.camera;
  const bool photo_out = c.plate.encoded && ibl::capture::is_photo_extension(o.out);
  if (photo_out && output_bits(o.out, c.plate) != c.plate.photo.bits)  // a 16-bit (or raw) backplate out as a JPEG
    ibl::capture::write_like(o.out, c.plate, ibl::capture::encode_like(c.plate, r.composite, 8), 8, o.quality);
  else if (photo_out)
    ibl::capture::write_like(o.out, c.plate, c.codes, 0, o.quality);
  else
    ibl::io::write_image(o.out, r.composite);
  if (!o.layers.empty()) {
    ibl::make_output_folders(fs::path(o.layers).string());
    fs::path dir(o.layers);
    ibl::io::write_image((dir / "probe.exr").string(), c.probe.probe.image);
    ibl::io::write_image((dir / "probe.png").string(), ibl::io::tonemap(c.probe.probe.image.with_channels(3)));
    ibl::io::write_image((dir / "probe_weights.exr").string(), c.probe.weights);
    // What another renderer needs to do the same composite: the light in the photograph's units (the match's gains
    // applied), the object's mesh, the proxy, the solved camera.
    ibl::io::write_image((dir / "probe_matched.exr").string(), c.light.map.image);
    ibl::geometry::write_obj((dir / "object.obj").string(), c.object, "composite --capture: the inserted object");
    ibl::geometry::write_obj((dir / "proxy.obj").string(), c.run.proxy, "composite --capture: the proxy");
    ibl::geometry::write_camera((dir / "camera.json").string(), cam, true);
    write_layer(dir, "mask", r.mask);
    write_layer(dir, "difference", r.difference);
    ibl::io::write_image((dir / "proxy_overlay.png").string(),
                         ibl::augment::proxy_overlay(ibl::io::tonemap(c.plate.linear), cam, c.run.proxy));
  }
  nlohmann::json merges = nlohmann::json::array();
  for (size_t k = 0; k < c.merges.size(); ++k)
    merges.push_back({{"dynamic_range_stops", c.merges[k].dynamic_range_stops},
                      {"saturated_everywhere", c.merges[k].saturated_everywhere},
                      {"ball", {c.circles[k].cx, c.circles[k].cy, c.circles[k].r}},
                      {"circle_residual_px", c.circle_residual_px[k]}});
  nlohmann::json j = {{"out", o.out},
                      {"capture", o.capture},
                      {"response", c.response_source},
                      {"views", merges},
                      {"probe_invalid_pixels", c.probe.invalid_pixels},
                      {"camera",
                       {{"eye", vec_json(cam.eye)},
                        {"target", vec_json(cam.target)},
                        {"fov_y_deg", cam.fov_y_deg},
                        {"lens", c.lens_source},
                        {"board_corners", c.board_corners},
                        {"board_corners_dropped", c.camera.dropped},
                        {"reprojection_rms_px", c.camera.error.rms_px},
                        {"reprojection_max_px", c.camera.error.max_px}}},
                      {"backend", ibl::augment::backend_name(c.run.backend)},
                      {"seconds", r.stats.seconds},
                      {"object_pixels", r.stats.object_pixels},
                      {"changed_pixels", r.stats.changed_pixels},
                      {"kept_pixels", c.report.kept},
                      {"encoded_pixels", c.report.encoded},
                      {"saturated_darkened", c.report.saturated_darkened},
                      {"warnings", r.warnings}};
  if (c.run.match.points > 0)
    j["match"] = {{"gain", vec_json(c.run.match.gain)},
                  {"stops", std::log2(ibl::luminance(c.run.match.gain))},
                  {"points", c.run.match.points},
                  {"spread_stops", c.run.match.spread},
                  {"applied", c.run.matched}};
  if (c.run.yaw.points > 0 || c.run.position.points > 0) j["registration"] = registration_json(c.run);
  // The lab's answers: the composite as written, in linear light, against the truth photographed through the same
  // camera; the camera against the exact one.
  ibl::augment::CompositeErrors e;
  double eye_mm = 0, view_deg = 0;
  const bool truth = !folder.truth.empty();
  if (truth) {
    const ibl::capture::Backplate t = ibl::capture::read_backplate(folder.at(folder.truth), c.plate.response);
    ibl::Image comp = photo_out ? ibl::capture::read_backplate(o.out, c.plate.response).linear : r.composite;
    ibl::Image mask = folder.truth_mask.empty() ? r.mask : ibl::io::read_image(folder.at(folder.truth_mask));
    if (mask.channels() > 1) mask = mask.with_channels(1);
    e = ibl::augment::measure(c.plate.linear, comp, t.linear, mask);
    j["errors"] = errors_json(e);
    if (!folder.truth_camera.empty()) {
      const ibl::geometry::Camera tc = ibl::geometry::read_camera(folder.at(folder.truth_camera));
      eye_mm = 1000 * ibl::length(cam.eye - tc.eye);
      const double cosv = ibl::dot(ibl::normalize(cam.target - cam.eye), ibl::normalize(tc.target - tc.eye));
      view_deg = std::acos(std::clamp(cosv, -1.0, 1.0)) * 180 / ibl::kPi;
      j["camera"]["eye_error_mm"] = eye_mm;
      j["camera"]["view_error_deg"] = view_deg;
      j["camera"]["fov_error_deg"] = cam.fov_y_deg - tc.fov_y_deg;
    }
    if (!o.layers.empty()) write_layer(o.layers, "truth_error", ibl::augment::error_picture(comp, t.linear));
  }
  iblcli::emit(j, [&] {
    fmt::print("composited the {} into {} ({}x{}) from {} in {:.2f} s: {}\n", folder.object,
               folder.at(folder.backplate), cam.width, cam.height, o.capture, r.stats.seconds, o.out);
    fmt::print("  response  {}\n", c.response_source);
    for (size_t k = 0; k < c.merges.size(); ++k)
      fmt::print("  view {}    {} frames, {:.1f} stops, ball {:.1f},{:.1f} r {:.1f} px{}\n", k,
                 folder.views[k].frames.size(), c.merges[k].dynamic_range_stops, c.circles[k].cx, c.circles[k].cy,
                 c.circles[k].r,
                 c.circle_residual_px[k] > 0 ? fmt::format(" (fit residual {:.2f} px)", c.circle_residual_px[k])
                                             : std::string());
    fmt::print(
        "  camera    eye {:.4f},{:.4f},{:.4f}, fov_y {:.3f}° ({}); {} board corners, reprojection {:.3f} px RMS\n",
        cam.eye.x, cam.eye.y, cam.eye.z, cam.fov_y_deg, c.lens_source, c.board_corners, c.camera.error.rms_px);
    if (c.run.match.points > 0)
      fmt::print("  match     gain {:.4g},{:.4g},{:.4g} ({:+.2f} stops) from {} proxy points{}\n", c.run.match.gain.x,
                 c.run.match.gain.y, c.run.match.gain.z, std::log2(ibl::luminance(c.run.match.gain)),
                 c.run.match.points, c.run.matched ? "" : " (not applied)");
    fmt::print("  {} object pixels, {} changed by its shadow and light, {} kept as photographed\n",
               r.stats.object_pixels, r.stats.changed_pixels, c.report.kept);
    if (truth) {
      fmt::print(
          "  against {}: object {:.1f} % ({} px), shadow {:.1f} % of the shadow signal ({} px, {:.0f} % darker), "
          "unchanged {:.2f} %\n",
          folder.truth, 100 * e.object, e.object_pixels, 100 * e.shadow, e.shadow_pixels, 100 * e.shadow_signal,
          100 * e.unchanged);
      if (!folder.truth_camera.empty())
        fmt::print("  camera against {}: eye {:.2f} mm, view {:.3f}°\n", folder.truth_camera, eye_mm, view_deg);
    }
  });
}

void setup(CLI::App& app) {
  auto* o = iblcli::app_owned<Opts>();
  app.add_option(
      "photo", o->photo,
      "the background photograph: HDR (linear), or 8-bit JPEG/PNG, 16-bit TIFF/PNG code values (--response)");
  app.add_option("--capture", o->capture,
                 "a capture folder (iblkit.capture/1: backplate, the ball's brackets, the board, the proxy; `lab shoot "
                 "--backplate` writes one): merge, probe from the ball, camera from the board, composite, in one go");
  app.add_flag(
      "--recover-response", o->recover_response,
      "--capture: recover the curve from the ball's first bracket (Debevec & Malik) even where the folder names "
      "one");
  app.add_option("--response", o->response,
                 "how the photograph's code values become linear: srgb (the default for 8/16-bit files), linear (the "
                 "default for float files), camera, or an iblkit.response/1 file (docs/formats.md)");
  app.add_option("--match", o->match,
                 "auto: the light's scale and per-channel gains estimated from the proxy points the photograph and the "
                 "probe both see, and applied (a probe's map; not an SH grid); grey-card: from --grey-card's pixels "
                 "alone; off: the light as captured")
      ->check(CLI::IsMember({"auto", "off", "grey-card"}))
      ->capture_default_str();
  app.add_option("--register", o->reg,
                 "the light's turn about +Y (which way the probe faced) from the proxy points the photograph and the "
                 "light both see, before the match: check (its turn and position measured, reported), yaw (the turn "
                 "applied), pose (its position and turn applied) or off (docs/augment.md)")
      ->check(CLI::IsMember({"off", "check", "yaw", "pose"}))
      ->capture_default_str();
  app.add_option(
      "--grey-card", o->grey_card,
      "x,y,w,h: pixels of a matte card (or any matte patch of the proxy) that the probe also sees: the match "
      "from them alone (--match grey-card)");
  app.add_option("--quality", o->quality,
                 "JPEG quality of a .jpg --out (default: the input JPEG's own, estimated from its tables; else 95)")
      ->check(CLI::Range(1, 100));
  iblcli::add_photo_scene_options(app, &o->scene, "");
  app.add_option("--light", o->light,
                 "an SH grid (.shgrid; built for the object: ilf build --focus AT,R) or a probe image (with "
                 "--at-probe), with --proxy");
  app.add_option("--probe-depth", o->probe_depth,
                 "the --light probe's depth map (metres; lights in front of the proxy)");
  auto& rd = iblcli::add_probe_read_options(app);
  app.add_option("--object", o->object, "blob, sphere, or a mesh file")->capture_default_str();
  app.add_option("--at", o->at, "where the object's centre goes")->capture_default_str();
  app.add_option("--object-size", o->job.object.size,
                 "largest extent, metres (0 keeps a mesh file's own size and place)")
      ->capture_default_str();
  app.add_option("--albedo", o->albedo, "the object's Lambertian albedo r,g,b")->capture_default_str();
  app.add_option("--gloss", o->gloss, "weight of the object's glossy lobe (0..1)")->check(CLI::Range(0.0, 1.0));
  app.add_option("--exponent", o->exponent, "exponent of the glossy lobe")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  app.add_option("--lobe", o->lobe, "glossy lobe: phong, or blinn (Blinn-Phong)")
      ->check(CLI::IsMember({"phong", "blinn"}))
      ->capture_default_str();
  app.add_option("--texture", o->texture,
                 "albedo texture of the object (sRGB PNG/JPG or linear EXR) at its UVs (the blob's and sphere's own)");
  app.add_option("--triangles", o->job.object.triangles, "triangles of the blob")
      ->check(CLI::Range(100, 5000000))
      ->capture_default_str();
  app.add_option("--samples", o->job.desc.light_samples, "light samples per proxy pixel (albedo and shadows)")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  app.add_option("--object-samples", o->job.desc.object_samples, "light samples per object pixel")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  app.add_option("--bounce-samples", o->job.desc.bounce_samples,
                 "cone samples per proxy pixel towards the object: its light on the pixel and, with the light samples, "
                 "its shadow (a square number is stratified; 0: no interreflection)")
      ->check(CLI::Range(0, 65536))
      ->capture_default_str();
  app.add_option("--pixel-samples", o->job.desc.pixel_samples, "n×n camera rays per pixel (object edges)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  app.add_option("--seed", o->job.desc.seed, "random seed")->capture_default_str();
  app.add_option("--median-cut", o->job.median_cut,
                 "baseline: the light cut into N median-cut lights (shadows and shading from those only)")
      ->check(CLI::Range(1, 4096));
  app.add_flag(
      "--no-shadows", [o](int64_t) { o->job.desc.shadows = false; },
      "baseline: the object pasted without its shadow and light on the scene");
  app.add_flag(
      "--no-self-light", [o](int64_t) { o->job.desc.self_light = false; },
      "leave out the object's light on itself (CPU; one bounce of it by default; GL never has it)");
  app.add_option("--backend", o->backend,
                 "cpu (the ray-traced reference), gl (OpenGL: shadow maps and a soft sphere term), auto (gl "
                 "when a GL context can be made)")
      ->capture_default_str();
#ifdef IBLKIT_HAVE_GL
  app.add_option("--gl-lights", o->job.desc.gl.split.lights, "gl: most hard lights with shadow maps")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--gl-threshold", o->job.desc.gl.split.threshold,
                 "gl: a texel brighter than this x the mean radiance is a hard light's")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--gl-visibility", o->job.desc.gl.visibility_samples,
                 "gl: rays per object triangle for the soft light that reaches it (its own "
                 "occlusion, the floor its shadow darkens, the parallax from the probe; 0: none; default: 4194304 rays "
                 "over the "
                 "triangles, 16 to 1024 each)")
      ->check(CLI::Range(0, 65536));
  app.add_option("--gl-soft-cutoff,--gl-cut", o->job.desc.gl.soft_cutoff,
                 "gl: the soft term is 0 where the object covers less than this cosine-weighted share of "
                 "the hemisphere (faded in up to twice it; the pixels left exactly as photographed)")
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();
  app.add_option("--shadow-map-size", o->job.desc.gl.shadow_map_size, "gl: texels per side of each light's shadow maps")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
#endif
  app.add_option("-o,--out", o->out,
                 "the composite: .exr linear; for an 8/16-bit photograph .jpg/.png/.tif back through --response in its "
                 "bit depth and metadata (unchanged pixels keep their codes); for an HDR one .png tone mapped")
      ->capture_default_str();
  app.add_option("--layers", o->layers,
                 "folder for mask, difference, albedo, render_with, render_without (.exr) and proxy_overlay.png (the "
                 "proxy's edges over the photograph)");
  iblcli::outputs(app, {"--layers"});  // besides --out (cli.h)
  app.add_option(
      "--truth", o->truth,
      "a photograph with the object really there (iblkit lab photograph): print the errors; repeat with other seeds to "
      "measure against their mean and estimate its noise");
  app.footer(
      "Examples:\n  iblkit composite photo.exr --eye 0,1.2,2.4 --target 0,0.3,0 --fov 40 --probes fusion/probes.json "
      "--object blob "
      "--at 0,0.2,0 --out comp.exr --layers layers\n"
      "  iblkit composite photo.exr --camera cam.json --light grid.shgrid --proxy room.obj --object sphere --at "
      "0,0.2,0\n"
      "  iblkit composite photo.exr --camera cam.json --light probe.exr --at-probe 0,0.5,0 --proxy floor.obj --at "
      "0,0.2,0");
  app.callback([o, &rd] {
    if (!o->capture.empty()) {
      if (!o->photo.empty())
        ibl::fail(ibl::ErrorKind::Value, "composite: give a photograph or --capture DIR, not both");
      run_capture(*o);
      return;
    }
    if (o->photo.empty()) ibl::fail(ibl::ErrorKind::Value, "composite: give the photograph (or --capture DIR)");
    run(*o, rd);
  });
}

iblcli::Command reg("composite", setup);

}  // namespace
#endif  // IBLKIT_HAVE_GEOMETRY
