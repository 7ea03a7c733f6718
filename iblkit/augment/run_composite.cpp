#include "iblkit/augment/run_composite.h"

#include <cmath>

#include <fmt/format.h>

#include "iblkit/core/error.h"

namespace ibl::augment {

const char* backend_name(Backend b) {
  switch (b) {
    case Backend::Cpu:
      return "cpu";
    case Backend::Gl:
      return "gl";
    case Backend::Auto:
      return "auto";
  }
  return "?";
}

Backend parse_backend(const std::string& name) {
  if (name == "cpu") return Backend::Cpu;
  if (name == "gl") return Backend::Gl;
  if (name == "auto") return Backend::Auto;
  fail(ErrorKind::Value, "backend {}: expected cpu, gl or auto", name);
}

Register parse_register(const std::string& name) {
  if (name == "off") return Register::Off;
  if (name == "check") return Register::Check;
  if (name == "yaw") return Register::Yaw;
  if (name == "pose") return Register::Pose;
  fail(ErrorKind::Value, "--register {}: expected off, check, yaw or pose", name);
}

namespace {

std::string offset_words(Vec3 o) { return fmt::format("({:+.3f}, {:+.3f}, {:+.3f}) m", o.x, o.y, o.z); }

void register_light(CompositeScene& s, const Image& photo, const geometry::Camera& cam, const CompositeJob& job) {
  if (job.reg == Register::Off) return;
  LocalRadiance& L = s.light.light;
  const bool pose = job.reg == Register::Pose, apply = job.reg == Register::Yaw || pose;
  auto too_few = [&](int64_t points) {
    s.notes.push_back(
        fmt::format("register: the photograph and the light see only {} proxy points in common (< {}): "
                    "the light is used as it was given",
                    points, kMinMatchPoints));
  };
  if (pose) {  // turn, position, turn again
    const YawFit y1 = register_yaw(photo, cam, s.light.proxy, L, job.saturated);
    if (!y1.valid) return too_few(y1.points);
    L = turned(L, y1.yaw_deg);
    s.position = register_position(photo, cam, s.light.proxy, L, job.saturated);
    if (s.position.valid) L.centre = L.centre + s.position.offset, s.moved = true;
    s.yaw = register_yaw(photo, cam, s.light.proxy, L, job.saturated);
    if (s.yaw.valid) L = turned(L, s.yaw.yaw_deg);
    s.yaw.yaw_deg = std::remainder(y1.yaw_deg + (s.yaw.valid ? s.yaw.yaw_deg : 0.0), 360.0);
    s.yaw.spread_given = y1.spread_given;
    s.turned = true;
    s.notes.push_back(
        fmt::format("register: the light turned {:+.1f}° about +Y and moved by {} to agree best with the photograph "
                    "(disagreement {:.3f} stops, {:.3f} as given) from {} proxy points",
                    s.yaw.yaw_deg, offset_words(s.position.offset), s.yaw.spread, s.yaw.spread_given, s.yaw.points));
    return;
  }
  s.yaw = register_yaw(photo, cam, s.light.proxy, L, job.saturated);
  if (!s.yaw.valid) return too_few(s.yaw.points);
  const YawFit& f = s.yaw;
  s.notes.push_back(fmt::format(
      "register: the light agrees best with the photograph turned {:+.1f}° about +Y (disagreement {:.3f} stops, "
      "{:.3f} as given; the best more than 20° away {:+.0f}°, {:.3f}) from {} proxy points: {}",
      f.yaw_deg, f.spread, f.spread_given, f.runner_up_deg, f.runner_up_spread, f.points,
      apply ? "turned" : "not applied (--register yaw turns it)"));
  if (apply) {
    L = turned(L, f.yaw_deg);
    s.turned = true;
    return;
  }
  s.position = register_position(photo, cam, s.light.proxy, L, job.saturated);
  if (s.position.valid)
    s.notes.push_back(fmt::format(
        "register: and moved by {} (disagreement {:.3f} stops, {:.3f} where given): not applied (--register pose moves "
        "and turns it; a chrome ball's probe sees from the ball's face, a few cm towards its cameras: docs/augment.md)",
        offset_words(s.position.offset), s.position.spread, s.position.spread_given));
}

}  // namespace

void match_light(CompositeScene& s, const Image& photo, const geometry::Camera& cam, const CompositeJob& job) {
  register_light(s, photo, cam, job);
  if (job.match == Match::Off) return;
  if (job.match == Match::Auto && s.light.light.source == "SH grid") return;  // a grid's map is band-limited
  const bool card = job.match == Match::GreyCard;
  s.match =
      estimate_match(photo, cam, s.light.proxy, s.light.light, job.saturated, 40000, card ? &job.grey_card : nullptr);
  if (card && !s.match.valid)
    fail(ErrorKind::Value,
         "--grey-card {},{},{},{}: only {} of its pixels show a proxy point the light also sees (at least {}): put the "
         "rectangle on the card as the photograph shows it, on the proxy",
         job.grey_card.x, job.grey_card.y, job.grey_card.w, job.grey_card.h, s.match.points, kMinCardPoints);
  if (!s.match.valid) {
    s.notes.push_back(fmt::format(
        "match: the photograph and the light see only {} proxy points in common (< {}): the light is used as "
        "captured",
        s.match.points, kMinMatchPoints));
    return;
  }
  s.light.light = scaled(s.light.light, s.match.gain);
  s.matched = true;
  const Vec3 g = s.match.gain;
  s.notes.push_back(fmt::format(
      "match: the light times ({:.4g}, {:.4g}, {:.4g}) ({:+.2f} stops) to the photograph's units, from {} proxy "
      "points both see (spread {:.2f} stops; --match off keeps it as captured)",
      g.x, g.y, g.z, std::log2(luminance(g)), s.match.points, s.match.spread));
}

CompositeScene prepare_composite(const CompositeJob& job, const Image* photo, const geometry::Camera* cam) {
  CompositeScene s;
  render::check_material(job.material);
  s.object = render::make_object(job.object);
  Vec3 lo, hi;
  s.object.bounds(&lo, &hi);
  s.light = load_light(job.light, lo, hi);
  if (job.median_cut < 0 || job.median_cut > 4096)
    fail(ErrorKind::Value, "median cut {} must lie in 0..4096", job.median_cut);
  if (photo && cam) match_light(s, *photo, *cam, job);
  if (job.median_cut > 0) s.light.light = as_median_cut(s.light.light, job.median_cut);
  return s;
}

#ifndef IBLKIT_HAVE_GL
bool gl_backend_available(std::string* why) {
  if (why) *why = "iblkit was built without OpenGL (IBLKIT_WITH_GL)";
  return false;
}
CompositeResult gl_backend_composite(const Image&, const geometry::Camera&, const geometry::TriMesh&,
                                     const LocalRadiance&, const geometry::TriMesh&, const render::Material&,
                                     const CompositeDesc&) {
  fail(ErrorKind::Unsupported, "the GL backend: iblkit was built without OpenGL (IBLKIT_WITH_GL)");
}
#endif

CompositeRun run_composite(const Image& photo, const geometry::Camera& cam, const CompositeJob& job,
                           const CompositeScene& scene) {
  CompositeRun run;
  run.backend = job.backend;
  if (cam.distorted()) {
    // The GL compositor rasterises through Camera::projection(), which cannot bend lines; the CPU casts
    // each pixel's ray (Camera::ray_direction), distortion and all.
    if (run.backend == Backend::Gl)
      fail(ErrorKind::Unsupported,
           "--backend gl cannot render through the camera's lens distortion (k1 k2 p1 p2 k3); use --backend cpu");
    if (run.backend == Backend::Auto) {
      run.backend = Backend::Cpu;
      run.notes.push_back("backend auto: the camera has lens distortion, which only the CPU composites");
    }
  }
  if (run.backend == Backend::Auto) {
    std::string why;
    run.backend = gl_backend_available(&why) ? Backend::Gl : Backend::Cpu;
    if (run.backend == Backend::Cpu)
      run.notes.push_back("backend auto: no OpenGL context (" + why + "): the CPU composites");
  }
  const LoadedLight& L = scene.light;
  run.result = run.backend == Backend::Gl
                   ? gl_backend_composite(photo, cam, L.proxy, L.light, scene.object, job.material, job.desc)
                   : composite(photo, cam, L.proxy, L.light, scene.object, job.material, job.desc);
  run.result.warnings.insert(run.result.warnings.begin(), L.warnings.begin(), L.warnings.end());
  run.light_source = L.light.source;
  run.proxy = L.proxy;
  run.match = scene.match;
  run.matched = scene.matched;
  run.yaw = scene.yaw;
  run.turned = scene.turned;
  run.position = scene.position;
  run.moved = scene.moved;
  run.notes.insert(run.notes.begin(), scene.notes.begin(), scene.notes.end());
  return run;
}

CompositeRun run_composite(const Image& photo, const geometry::Camera& cam, const CompositeJob& job) {
  return run_composite(photo, cam, job, prepare_composite(job, &photo, &cam));
}

}  // namespace ibl::augment
