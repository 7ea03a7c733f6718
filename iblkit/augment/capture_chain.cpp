#include "iblkit/augment/capture_chain.h"

#include <cmath>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/render/objects.h"

namespace ibl::augment {

namespace {

// The folder's response for the ball and the backplate: named, or recovered from view 0's bracket.
capture::Response chain_response(const capture::CaptureFolder& f, const capture::Bracket& view0, bool recover,
                                 std::string* source) {
  if (view0.linear) {  // raw files: linear, nothing to recover
    *source = "linear (raw files)";
    return capture::linear_response();
  }
  if (!f.response.empty() && !recover) {
    const bool named = f.response == "srgb" || f.response == "linear" || f.response == "camera";
    *source = named ? f.response : f.at(f.response);
    return capture::response_by_name(*source);
  }
  capture::MergeDesc md;
  md.align = false;
  capture::MergeReport r;
  capture::merge_hdr(view0.frames, md, &r);
  *source = fmt::format("recovered (Debevec & Malik) from view 0's {} frames", view0.frames.size());
  return r.response;
}

// The backplate's lens, with where it came from.
geometry::Camera chain_lens(const capture::CaptureFolder& f, const capture::Backplate& plate, bool exif,
                            capture::LensMode* mode, std::string* source) {
  geometry::Camera lens;
  lens.width = plate.linear.width();
  lens.height = plate.linear.height();
  *mode = capture::LensMode::Fixed;
  if (!f.lens.empty()) {
    const geometry::Camera k = geometry::read_camera(f.at(f.lens));
    if (!k.intrinsics) fail(ErrorKind::Value, "{}: the lens file has no \"intrinsics\"", f.at(f.lens));
    if (k.width != lens.width || k.height != lens.height)
      fail(ErrorKind::Value, "{}: calibrated for {}x{}, but {} is {}x{}", f.at(f.lens), k.width, k.height, plate.path,
           lens.width, lens.height);
    lens.intrinsics = k.intrinsics;
    lens.distortion = k.distortion;
    lens.fov_y_deg = k.fov_y_deg;
    *source = "the lens file " + f.lens;
    return lens;
  }
  std::optional<capture::ExifLens> e;
  if (exif && plate.encoded) e = capture::lens_from_exif(plate.photo.meta, lens.width, lens.height);
  if (f.fov_deg > 0) {
    if (e && std::abs(e->fov_y_deg - f.fov_deg) > 1)
      fail(ErrorKind::Value, "{}: \"fov_deg\" {}° contradicts the backplate's Exif ({}: {:.2f}°); drop one of them",
           f.at("capture.json"), f.fov_deg, e->source, e->fov_y_deg);
    lens.fov_y_deg = f.fov_deg;
    *source = fmt::format("fov_deg {}°", f.fov_deg);
    return lens;
  }
  if (e) {
    lens.fov_y_deg = e->fov_y_deg;
    *source = fmt::format("{} (fov_y {:.4f}°)", e->source, e->fov_y_deg);
    return lens;
  }
  *mode = capture::LensMode::SolveFocal;
  *source =
      "focal length solved with the pose (one view of a planar board leaves it loose: give \"fov_deg\" or "
      "\"lens\")";
  return lens;
}

}  // namespace

ChainResult run_capture(const capture::CaptureFolder& f, const ChainDesc& d) {
  ChainResult out;
  out.folder = f;
  auto progress = [&](std::string_view what, double x) { report(d.job.desc.progress, what, x); };
  // 1. The brackets, merged through one curve.
  std::vector<capture::Bracket> brackets;
  for (const capture::CaptureView& v : f.views) {
    std::vector<std::string> files;
    for (const std::string& fr : v.frames) files.push_back(f.at(fr));
    brackets.push_back(capture::read_bracket(files, {}));
  }
  progress("merge", 0);
  out.response = chain_response(f, brackets[0], d.recover_response, &out.response_source);
  for (const auto& b : brackets)
    if (!b.linear) capture::check_fits(out.response, b.bits, b.frames.at(0).name, out.response_source);
  std::vector<capture::BallView> views;
  for (size_t k = 0; k < f.views.size(); ++k) {
    capture::MergeDesc md;
    md.response = out.response;
    capture::MergeReport r;
    Image hdr = capture::merge_hdr(brackets[k].frames, md, &r);
    out.merges.push_back(r);
    const capture::CaptureView& v = f.views[k];
    capture::BallView bv;
    bv.name = f.at(v.frames[0]);
    if (v.ball) {
      bv.ball = *v.ball;
      out.circle_residual_px.push_back(0);
    } else {
      const capture::CircleFit fit = capture::find_ball(hdr, bv.name, "the view's \"circle\"");
      bv.ball = fit.circle;
      out.circle_residual_px.push_back(fit.residual_px);
    }
    out.circles.push_back(bv.ball);
    bv.distance = v.distance_radii > 0 ? v.distance_radii
                                       : capture::distance_from_lens(bv.ball.r, hdr.width(), v.focal_mm, v.sensor_mm);
    bv.angle_deg = v.angle_deg;
    bv.photo = std::move(hdr);
    views.push_back(std::move(bv));
  }
  // 2. The probe, in the world.
  progress("probe", 0.15);
  capture::FromBallDesc fd;
  fd.size = d.probe_size;
  fd.samples = d.probe_samples;
  fd.rotation = capture::ball_frame(f.facing);
  capture::parse_fresnel(f.fresnel, &fd.reflectance, f.at("capture.json") + ": ball.fresnel");
  fd.reflectance.r0 = f.reflectance;
  out.probe = capture::probe_from_ball(views, fd);
  views.clear();
  // 3. The backplate through the same curve, and its camera from the board.
  progress("camera", 0.25);
  out.plate = capture::read_backplate(f.at(f.backplate), out.response);
  if (out.plate.encoded && !out.plate.photo.linear)
    capture::check_fits(out.response, out.plate.photo.bits, f.at(f.backplate), out.response_source);
  capture::LensMode mode;
  const geometry::Camera lens = chain_lens(f, out.plate, d.exif_lens, &mode, &out.lens_source);
  auto pts = capture::find_board(out.plate.linear, f.board);
  if (!pts)
    fail(ErrorKind::Value, "{}: no {} ({}) found ({})", f.at(f.backplate), f.board.describe(), f.board_spec,
         f.board.find_hint());
  out.board_corners = pts->size();
  out.camera = capture::solve_board_camera(f.board, *pts, lens, mode);
  const Vec3 n = cross(f.board.u, f.board.v);
  if (n.y < -0.9 && out.camera.camera.eye.y < f.board.origin.y)
    fail(ErrorKind::Value,
         "{}: the board's axes put the camera under the floor: give axes whose u × v points up (out of the printed "
         "face)",
         f.at("capture.json"));
  if (!(out.camera.error.rms_px <= d.max_error_px))
    fail(ErrorKind::Value, "{}: the board's corners disagree with one camera: {:.3g} px RMS exceeds {} px",
         f.at(f.backplate), out.camera.error.rms_px, d.max_error_px);
  const geometry::Camera& cam = out.camera.camera;
  // 4. The composite.
  CompositeJob job = d.job;
  job.object = {f.object, f.object_size, job.object.triangles, f.object_at};
  job.material.albedo = f.albedo;
  render::check_material(job.material, f.at("capture.json") + ": object.albedo");
  CompositeScene scene;
  scene.object = render::make_object(job.object);
  LocalRadiance& light = scene.light.light;
  light.centre = f.ball_center;
  light.source = "chrome ball";
  const Image& rgba = out.probe.probe.image;
  Image rgb(rgba.width(), rgba.height(), 3);
  for (int y = 0; y < rgba.height(); ++y)
    for (int x = 0; x < rgba.width(); ++x) rgb.set_rgb(x, y, rgba.rgb(x, y));
  light.map = sphere::EnvMap(std::move(rgb), out.probe.probe.mapping);
  scene.light.proxy = geometry::read_mesh(f.at(f.proxy));
  if (out.plate.encoded) {  // the photograph's top code, linear: saturated pixels say nothing of the light's scale
    job.saturated = 1e30;
    for (int c = 0; c < 3; ++c) job.saturated = std::min(job.saturated, out.plate.response.invert(1.0, c) * (1 - 1e-6));
  }
  match_light(scene, out.plate.linear, cam, job);
  job.desc.progress = [&](std::string_view what, double x) { report(d.job.desc.progress, what, 0.3 + 0.7 * x); };
  out.run = run_composite(out.plate.linear, cam, job, scene);
  out.light = scene.light.light;
  out.object = std::move(scene.object);
  if (out.plate.encoded) out.codes = capture::encode_like(out.plate, out.run.result.composite, 0, &out.report);
  return out;
}

}  // namespace ibl::augment
