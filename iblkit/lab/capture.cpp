#include "iblkit/lab/capture.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/lab/radiance.h"

namespace ibl::lab {

using sphere::MappingKind;

sphere::Mapping capture_mapping(MappingKind k, int size, double dead_angle_deg) {
  if (size < 1 || size > 16384) fail(ErrorKind::Value, "capture size {} is out of range [1, 16384]", size);
  switch (k) {
    case MappingKind::LatLong:
      return {k, 2 * size, size};
    case MappingKind::CubeHCross:
      return {k, 4 * size, 3 * size};
    case MappingKind::CubeVCross:
      return {k, 3 * size, 4 * size};
    case MappingKind::CubeStrip:
      return {k, 6 * size, size};
    default:
      return {k, size, size, dead_angle_deg};
  }
}

namespace {

// A ray of the physical mirror-ball camera through image point (px, py): the orthographic ray along
// −Z reflects off the ball at normal n = (x, y, √(1−x²−y²)) into d = (0,0,−1) + 2 n_z n.
bool ball_ray(const sphere::Mapping& m, double px, double py, Vec3* n, Vec3* d) {
  double x = 2 * px / m.width() - 1, y = 1 - 2 * py / m.height(), r2 = x * x + y * y;
  if (r2 >= 1) return false;
  *n = {x, y, std::sqrt(1 - r2)};
  *d = Vec3{0, 0, -1} + *n * (2 * n->z);
  return true;
}

constexpr int kMinAperturePoints = 256, kAperturePointsPerPixel = 16;  // equal-area strata of the disc
constexpr double kShadowShorten = 1e-4;  // relative: as radiance.cpp, stop short of the aperture

// Whether a world direction carries light under desc.cone.
bool cone_selects(const CaptureDesc& desc, Vec3 d) {
  if (desc.cone == CaptureDesc::Cone::All) return true;
  bool inside = dot(d, desc.cone_axis) > std::cos(desc.cone_deg * kPi / 180);
  return inside == (desc.cone == CaptureDesc::Cone::Inside);
}

// Lamps whose aperture is small in this capture (see kSmallApertureFactor): bit i = emitters[i];
// rings[i] = the number of rings (and sectors) of its points.
uint64_t small_apertures(const Scene& scene, Vec3 position, const CaptureDesc& desc, const sphere::Mapping& m,
                         std::vector<int>& rings) {
  uint64_t mask = 0;
  rings.assign(std::min<size_t>(scene.emitters.size(), 64), 0);
  if (!desc.integrate_apertures || desc.camera != Camera::Ideal) return mask;
  const double mean_pixel = 4 * kPi / (static_cast<double>(m.width()) * m.height());
  for (size_t i = 0; i < scene.emitters.size() && i < 64; ++i) {
    const Emitter& e = scene.emitters[i];
    if ((e.type != EmitterType::Spot && e.type != EmitterType::Projector) || e.aperture_radius <= 0) continue;
    Vec3 w = e.position - position;
    double d = length(w);
    if (d <= 2 * e.aperture_radius) continue;  // the lamp fills much of the view: pixels resolve it
    w = w / d;
    double omega = e.emit_area * std::abs(dot(w, e.direction)) / (d * d);
    double px, py, pixel = mean_pixel;
    if (m.to_pixel(desc.rotation.transposed() * w, &px, &py)) {
      int x = std::clamp(static_cast<int>(px), 0, m.width() - 1),
          y = std::clamp(static_cast<int>(py), 0, m.height() - 1);
      if (m.solid_angle_estimate(x, y) > 0) pixel = m.solid_angle_estimate(x, y);
    }
    if (omega < kSmallApertureFactor * pixel) {
      mask |= uint64_t{1} << i;
      double points = std::max<double>(kMinAperturePoints, kAperturePointsPerPixel * omega / pixel);
      rings[i] = static_cast<int>(std::ceil(std::sqrt(points)));
    }
  }
  return mask;
}

// Adds the light of lamp e's aperture to the pixels it falls in: K equal-area points q on the disc,
// each visible one carrying E = I(−ω)/(K·|q − o|²) into the pixel of ω, divided by that pixel's solid
// angle (a pixel holds the mean radiance over its solid angle).
void add_aperture(const Scene& scene, const Emitter& e, int rings, Vec3 o, const CaptureDesc& desc,
                  const sphere::Mapping& m, Image& img) {
  const Frame f = Frame::from_normal(e.direction);
  const Mat3 to_probe = desc.rotation.transposed();
  const int sectors = rings, K = rings * sectors;
  for (int i = 0; i < rings; ++i) {
    double r = e.aperture_radius * std::sqrt((i + 0.5) / rings);
    for (int j = 0; j < sectors; ++j) {
      double phi = 2 * kPi * (j + 0.5) / sectors;
      Vec3 q = e.position + (f.t * std::cos(phi) + f.b * std::sin(phi)) * r;
      Vec3 w = q - o;
      double d2 = dot(w, w), dist = std::sqrt(d2);
      w = w / dist;
      if (-dot(w, e.direction) <= 0) continue;  // behind the lamp: the disc emits from its front only
      Vec3 I = e.intensity_towards(-w);
      if (max_component(I) <= 0 || scene.tracer().occluded(o, w, 0, dist * (1 - kShadowShorten))) continue;
      double px, py;
      Vec3 local = to_probe * w;
      if (!cone_selects(desc, w)) continue;
      if (!m.to_pixel(local, &px, &py)) continue;  // a direction without data (dead angle)
      int x = std::clamp(static_cast<int>(px), 0, m.width() - 1),
          y = std::clamp(static_cast<int>(py), 0, m.height() - 1);
      double sa = m.solid_angle(x, y);
      if (sa <= 0) continue;
      img.set_rgb(x, y, img.rgb(x, y) + I / (K * d2 * sa));
    }
  }
}

}  // namespace

Capture capture_probe(const Scene& scene, Vec3 position, const CaptureDesc& desc, uint64_t probe_index,
                      const ProgressFn& progress) {
  if (!scene.built()) fail(ErrorKind::Internal, "capture_probe: scene {} is not built", scene.name);
  require_point("capture position", position);
  if (desc.samples < 1 || desc.samples > 64)
    fail(ErrorKind::Value, "samples per pixel axis {} is out of range [1, 64]", desc.samples);
  bool ball = desc.camera == Camera::MirrorBall;
  if (ball && desc.mapping != MappingKind::MirrorBall)
    fail(ErrorKind::Value, "the mirror-ball camera makes mirrorball images, not {}",
         sphere::mapping_name(desc.mapping));
  if (desc.cone != CaptureDesc::Cone::All && (ball || !(desc.cone_deg > 0 && desc.cone_deg < 180)))
    fail(ErrorKind::Value, "a cone selection needs the ideal camera and a half-angle in (0, 180), got {}",
         desc.cone_deg);
  if (ball && !(desc.ball_radius >= 0)) fail(ErrorKind::Value, "ball radius {} must be ≥ 0", desc.ball_radius);
  if (ball && !(desc.ball_reflectance >= 0 && desc.ball_reflectance <= 1))
    fail(ErrorKind::Value, "ball reflectance {} must lie in [0, 1]", desc.ball_reflectance);
  if (desc.render.area_samples < 1 || desc.render.env_samples < 1 || desc.render.bounces < 0 ||
      desc.render.bounces > 64)
    fail(ErrorKind::Value, "need area samples ≥ 1, environment samples ≥ 1 and 0 ≤ bounces ≤ 64 (got {}, {}, {})",
         desc.render.area_samples, desc.render.env_samples, desc.render.bounces);
  Capture cap;
  cap.mapping = capture_mapping(desc.mapping, desc.size, ball ? 0.0 : desc.dead_angle_deg);
  const sphere::Mapping& m = cap.mapping;
  const int W = m.width(), H = m.height(), n = desc.samples;
  cap.radiance = Image(W, H, 3);
  if (desc.depth) cap.depth = Image(W, H, 1);
  std::vector<int> rings;
  const uint64_t hidden = small_apertures(scene, position, desc, m, rings);
  std::atomic<int> rows_done{0};
  parallel_for(0, H, [&](int64_t y) {
    for (int x = 0; x < W; ++x) {
      uint64_t pixel = static_cast<uint64_t>(y) * W + x;
      Vec3 sum;
      int used = 0;
      for (int s = 0; s < n * n; ++s) {
        double px = x + (s % n + 0.5) / n, py = y + (s / n + 0.5) / n;
        Rng rng(stream_key(desc.render.seed, probe_index, pixel, s));
        Vec3 d, o = position, nb;
        if (ball) {
          ++used;  // sub-samples that miss the ball see nothing (a black backdrop)
          if (!ball_ray(m, px, py, &nb, &d)) continue;
          if (desc.ball_parallax) o = position + desc.rotation * nb * desc.ball_radius;
          sum += radiance(scene, o, desc.rotation * d, rng, desc.render) * desc.ball_reflectance;
        } else {
          if (!m.to_direction(px, py, &d)) continue;
          ++used;
          if (!cone_selects(desc, desc.rotation * d)) continue;
          sum += radiance(scene, o, desc.rotation * d, rng, desc.render, hidden);
        }
      }
      if (used) cap.radiance.set_rgb(x, static_cast<int>(y), sum / used);
      if (desc.depth) {
        Vec3 d, o = position, nb;
        bool ok = ball ? ball_ray(m, x + 0.5, y + 0.5, &nb, &d) : m.to_direction(x + 0.5, y + 0.5, &d);
        if (ok) {
          if (ball && desc.ball_parallax) o = position + desc.rotation * nb * desc.ball_radius;
          double t = first_hit_distance(scene, o, desc.rotation * d);
          cap.depth.at(x, static_cast<int>(y), 0) = std::isfinite(t) ? static_cast<float>(t) : 0.0f;
        }
      }
    }
    if (progress) report(progress, "capture", static_cast<double>(++rows_done) / H);
  });
  for (size_t i = 0; i < scene.emitters.size() && i < 64; ++i)
    if ((hidden >> i) & 1) add_aperture(scene, scene.emitters[i], rings[i], position, desc, m, cap.radiance);
  return cap;
}

}  // namespace ibl::lab
