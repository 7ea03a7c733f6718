#include "iblkit/lab/shoot.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/core/rng.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/ilf/ball.h"
#include "iblkit/lab/radiance.h"
#include "iblkit/lab/view.h"

namespace ibl::lab {

namespace {

// A box given in the camera's frame (x right, y up, z backwards, away from the ball), placed at the eye.
geometry::TriMesh camera_box(Vec3 lo, Vec3 hi, const Mat3& frame, Vec3 eye) {
  geometry::TriMesh m = geometry::make_box(lo, hi);
  m.transform(frame, 1.0, eye);
  return m;
}

}  // namespace

std::vector<Shot> shoot(const Scene& base, const ShootDesc& d, const ProgressFn& progress) {
  if (base.built()) fail(ErrorKind::Internal, "lab::shoot takes a scene that is not built yet");
  require_point("ball centre", d.ball_center);
  if (!(d.ball_radius > 0 && d.ball_radius < 1e3))
    fail(ErrorKind::Value, "ball radius {} m must be positive (--ball-radius)", d.ball_radius);
  if (!(d.distance > d.ball_radius * 1.0001 && d.distance < 1e4))
    fail(ErrorKind::Value, "camera distance {} m must exceed the ball's radius {} m (--distance)", d.distance,
         d.ball_radius);
  if (d.width < 8 || d.height < 8 || d.width > 16384 || d.height > 16384)
    fail(ErrorKind::Value, "photograph size {}x{} is out of range [8, 16384] (--width, --height)", d.width, d.height);
  if (d.samples < 1 || d.samples > 16) fail(ErrorKind::Value, "samples {} out of range [1, 16] (--samples)", d.samples);
  if (!(d.fill > 0 && d.fill <= 1)) fail(ErrorKind::Value, "--fill {} must lie in (0, 1]", d.fill);
  if (!(std::abs(d.elevation_deg) < 89))
    fail(ErrorKind::Value, "--elevation {}° must lie in (−89°, 89°)", d.elevation_deg);
  if (d.views_deg.empty()) fail(ErrorKind::Value, "lab shoot: no views");
  const double az = d.azimuth_deg * kPi / 180, el = d.elevation_deg * kPi / 180;
  const Vec3 dir0{std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
  const double alpha = std::asin(d.ball_radius / d.distance);
  const double fov = 2 * std::atan(std::tan(alpha) / d.fill) * 180 / kPi;
  const ilf::BallOptics optics{d.ball_radius, d.distance};
  std::vector<Shot> shots;
  int view_index = 0;
  for (double angle : d.views_deg) {
    Shot s;
    s.angle_deg = angle;
    s.distance_radii = d.distance / d.ball_radius;
    const Vec3 Z = normalize(Mat3::rotation({0, 1, 0}, angle * kPi / 180) * dir0);
    const Vec3 X = normalize(cross(Vec3{0, 1, 0}, Z)), Y = cross(Z, X);
    s.ball_frame = Mat3::rows(X, Y, Z).transposed();  // columns: the frame's axes in the world
    const Vec3 eye = d.ball_center + Z * d.distance;
    s.camera.eye = eye;
    s.camera.target = d.ball_center;
    s.camera.up = {0, 1, 0};
    s.camera.fov_y_deg = fov;
    s.camera.width = d.width;
    s.camera.height = d.height;
    geometry::require_camera(s.camera);
    s.ball = {d.width / 2.0, d.height / 2.0, d.fill * d.height / 2.0};
    Scene scene = base;
    int body = -1, person = -1;
    if (d.photographer) {
      body = add_object(scene, "camera body", camera_box({-0.07, -0.05, 0.002}, {0.07, 0.05, 0.10}, s.ball_frame, eye),
                        {0.03, 0.03, 0.03});
      person = add_object(scene, "photographer",
                          camera_box({-0.25, -1.55, 0.12}, {0.25, 0.25, 0.42}, s.ball_frame, eye), {0.08, 0.07, 0.06});
    }
    scene.build();
    const int W = d.width, H = d.height, n = d.samples;
    s.radiance = Image(W, H, 3);
    s.occluder = Image(W, H, 1);
    const Mat3 to_ball = s.ball_frame.transposed();
    std::atomic<int> rows{0};
    parallel_for(0, H, [&](int64_t yy) {
      const int y = static_cast<int>(yy);
      for (int x = 0; x < W; ++x) {
        const uint64_t pixel = static_cast<uint64_t>(y) * W + x;
        Vec3 sum;
        int occluded = 0;
        for (int k = 0; k < n * n; ++k) {
          Vec3 dir = s.camera.ray_direction(x + (k % n + 0.5) / n, y + (k / n + 0.5) / n);
          Rng rng(stream_key(d.render.seed, 0x73686f74u + view_index, pixel, k));
          Vec3 start, refl;
          if (ilf::ball_reflect(optics, to_ball * dir, &start, &refl)) {
            Vec3 o = d.ball_center + s.ball_frame * start, w = normalize(s.ball_frame * refl);
            Vec3 R = d.reflectance.at(-dot(to_ball * dir, start) / d.ball_radius);
            Vec3 L = radiance(scene, o, w, rng, d.render);
            sum += Vec3{L.x * R.x, L.y * R.y, L.z * R.z};
            if (d.photographer) {
              geometry::Hit h = scene.tracer().intersect(o, w);
              occluded += h.hit && (static_cast<int>(h.mesh) == body || static_cast<int>(h.mesh) == person);
            }
          } else {
            sum += radiance(scene, eye, dir, rng, d.render);
          }
        }
        s.radiance.set_rgb(x, y, sum / (n * n));
        s.occluder.at(x, y, 0) = static_cast<float>(occluded) / (n * n);
      }
      report(progress, "shoot", (view_index + static_cast<double>(++rows) / H) / d.views_deg.size());
    });
    shots.push_back(std::move(s));
    ++view_index;
  }
  return shots;
}

std::vector<double> bracket_times(int n, double ev_step, double middle_s) {
  if (n < 1 || n > 64) fail(ErrorKind::Value, "bracket of {} frames is out of range [1, 64] (--bracket)", n);
  if (!(ev_step > 0 && ev_step <= 8)) fail(ErrorKind::Value, "EV step {} must lie in (0, 8] (--ev-step)", ev_step);
  if (!(middle_s > 0 && std::isfinite(middle_s))) fail(ErrorKind::Value, "exposure {} s must be positive", middle_s);
  std::vector<double> t;
  for (int k = 0; k < n; ++k) t.push_back(middle_s * std::exp2(ev_step * (k - (n - 1) / 2.0)));
  return t;
}

std::vector<double> bracket_until_unsaturated(const Image& radiance, const capture::SensorDesc& s, double longest_s,
                                              double ev_step, int max_frames) {
  if (!(ev_step > 0 && ev_step <= 8)) fail(ErrorKind::Value, "EV step {} must lie in (0, 8] (--ev-step)", ev_step);
  if (!(longest_s > 0 && std::isfinite(longest_s))) fail(ErrorKind::Value, "exposure {} s must be positive", longest_s);
  if (max_frames < 2 || max_frames > 64)
    fail(ErrorKind::Value, "bracket of at most {} frames is out of range [2, 64] (--bracket)", max_frames);
  double peak = 0;
  for (size_t i = 0; i < radiance.pixel_count(); ++i) {
    const float* p = radiance.data() + i * radiance.channels();
    peak = std::max({peak, p[0] * s.wb_gains.x, p[1] * s.wb_gains.y, p[2] * s.wb_gains.z});
  }
  const double per_second = (s.iso / 100.0) / (s.f_number * s.f_number);
  std::vector<double> t;
  for (int k = 0; k < max_frames; ++k) {
    t.push_back(longest_s * std::exp2(-ev_step * k));
    if (t.size() >= 2 && peak * t.back() * per_second < 0.9) return t;
  }
  fail(ErrorKind::Value,
       "{} frames {} stops apart do not reach an exposure without saturated pixels (the brightest needs {:.3g} s): "
       "allow more frames (--bracket) or a larger --ev-step",
       max_frames, ev_step, 0.9 / (peak * per_second));
}

double middle_grey_exposure(const Image& radiance, const capture::BallCircle& ball, const capture::SensorDesc& s) {
  std::vector<double> lum;
  for (int y = 0; y < radiance.height(); ++y)
    for (int x = 0; x < radiance.width(); ++x)
      if (std::hypot(x + 0.5 - ball.cx, y + 0.5 - ball.cy) < ball.r) lum.push_back(luminance(radiance.rgb(x, y)));
  if (lum.empty()) fail(ErrorKind::Value, "the ball covers no pixel");
  std::nth_element(lum.begin(), lum.begin() + lum.size() / 2, lum.end());
  double med = lum[lum.size() / 2];
  if (!(med > 0)) fail(ErrorKind::Value, "the ball is black in the linear photograph: give the exposure (--exposure)");
  return 0.18 * s.f_number * s.f_number / (s.iso / 100.0) / med;
}

std::vector<BracketFrame> bracket(const Image& radiance, const BracketDesc& desc) {
  if (desc.exposures_s.empty()) fail(ErrorKind::Value, "a bracket needs at least one exposure");
  if (desc.shift_px < 0 || desc.shift_px > 256)
    fail(ErrorKind::Value, "hand-held shift {} px is out of range [0, 256] (--shift)", desc.shift_px);
  Rng rng(stream_key(desc.sensor.seed, 0x7368696674u /* "shift" */, 0, 0));
  std::vector<BracketFrame> frames;
  const int W = radiance.width(), H = radiance.height();
  for (size_t k = 0; k < desc.exposures_s.size(); ++k) {
    BracketFrame f;
    f.exposure_s = desc.exposures_s[k];
    if (k > 0 && desc.shift_px > 0) {
      f.dx = static_cast<int>(std::floor(rng.uniform() * (2 * desc.shift_px + 1))) - desc.shift_px;
      f.dy = static_cast<int>(std::floor(rng.uniform() * (2 * desc.shift_px + 1))) - desc.shift_px;
    }
    Image moved = radiance;
    if (f.dx != 0 || f.dy != 0)
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
          moved.set_rgb(x, y, radiance.rgb(std::clamp(x - f.dx, 0, W - 1), std::clamp(y - f.dy, 0, H - 1)));
    capture::SensorDesc s = desc.sensor;
    s.exposure_s = f.exposure_s;
    s.seed = desc.sensor.seed + k;
    if (desc.raw)
      f.raw = capture::expose_dng(moved, s, *desc.raw, {});
    else
      f.codes = capture::expose(moved, s);
    frames.push_back(std::move(f));
  }
  return frames;
}

}  // namespace ibl::lab
