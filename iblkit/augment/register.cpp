#include "iblkit/augment/register.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"

namespace ibl::augment {

Vec3 turn_y(Vec3 d, double deg) {
  const double a = deg * kPi / 180, c = std::cos(a), s = std::sin(a);
  return {c * d.x + s * d.z, d.y, -s * d.x + c * d.z};
}

namespace {

// How far the photograph and the light turned by `deg` disagree over the points the turned light sees: the mean
// absolute deviation of log2(photo / light) (luminance) from its median, over the 90 % of points nearest it (a lamp
// seen by one and not the other, a glossy patch, stay out). The match's median spread alone is flat across a degree
// or more: most points lie on evenly lit walls and floor, and only the edges of the pools of light tell the turn.
// With `offset`, the light stands at its centre + offset (the points are where they were: the photograph's).
double spread_at(const std::vector<SeenPoint>& pts, const LocalRadiance& light, double floor, double deg, int64_t* n,
                 Vec3 offset = {0, 0, 0}) {
  std::vector<double> lr;
  lr.reserve(pts.size());
  const bool moved = offset.x != 0 || offset.y != 0 || offset.z != 0;
  for (const SeenPoint& p : pts) {
    SeenPoint q = p;
    if (moved) {
      const Vec3 w = p.dir * p.dist - offset;
      q.dist = length(w);
      if (!(q.dist > 1e-6)) continue;
      q.dir = w / q.dist;
    }
    Vec3 lp;
    // The turned light towards dir is the given one towards R⁻¹ dir.
    if (!light_at(light, q, turn_y(q.dir, -deg), floor, &lp)) continue;
    lr.push_back(std::log2(luminance(p.photo) / luminance(lp)));
  }
  *n = static_cast<int64_t>(lr.size());
  if (lr.empty()) return 1e300;
  auto mid = lr.begin() + static_cast<std::ptrdiff_t>(lr.size() / 2);
  std::nth_element(lr.begin(), mid, lr.end());
  const double m = *mid;
  for (double& v : lr) v = std::abs(v - m);
  const size_t keep = std::max<size_t>(1, lr.size() * 9 / 10);
  std::nth_element(lr.begin(), lr.begin() + static_cast<std::ptrdiff_t>(keep - 1), lr.end());
  double sum = 0;
  for (size_t i = 0; i < keep; ++i) sum += lr[i];
  return sum / static_cast<double>(keep);
}

// The points both see, traced once from the light's centre, the light's floor, an even subset of at most `few` of
// them for a coarse search (with the count a subset's evaluation needs to stand for kMinMatchPoints), and the
// disagreement with the light as given (turned by given_deg) over all of them.
struct Seen {
  std::vector<SeenPoint> all, some;
  double floor = 0, given = 0;
  int64_t min_some = 0, given_points = 0;
};
Seen seen_for(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
              const LocalRadiance& light, double saturated, size_t few, double given_deg) {
  Seen s;
  s.all = seen_points(photo, cam, proxy, light.centre, saturated, 40000, nullptr);
  s.floor = light_floor_of(light);
  const size_t every = std::max<size_t>(1, s.all.size() / few);
  for (size_t i = 0; i < s.all.size(); i += every) s.some.push_back(s.all[i]);
  s.min_some = std::max<int64_t>(kMinMatchPoints / static_cast<int64_t>(every), 16);
  s.given = spread_at(s.all, light, s.floor, given_deg, &s.given_points);
  return s;
}

}  // namespace

YawFit register_yaw(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                    const LocalRadiance& light, double saturated, double range_deg) {
  if (!(range_deg > 0 && range_deg <= 180))
    fail(ErrorKind::Value, "register: range {}° must lie in (0, 180]", range_deg);
  // The coarse search on at most 10,000 of the points, evenly taken; the refinement on all of them.
  const Seen seen = seen_for(photo, cam, proxy, light, saturated, 10000, 0);
  YawFit f;
  f.spread_given = seen.given;
  f.points = seen.given_points;
  if (f.points < kMinMatchPoints) return f;
  const std::vector<SeenPoint>&pts = seen.all, &some = seen.some;
  const double floor = seen.floor;
  const int steps = static_cast<int>(std::floor(range_deg));
  std::vector<double> deg, val(static_cast<size_t>(2 * steps + 1));
  for (int k = -steps; k <= steps; ++k) deg.push_back(k);
  parallel_for(0, static_cast<int64_t>(deg.size()), [&](int64_t i) {
    int64_t n = 0;
    const double v = spread_at(some, light, floor, deg[i], &n);
    val[i] = n >= seen.min_some ? v : 1e300;
  });
  const size_t best = static_cast<size_t>(std::min_element(val.begin(), val.end()) - val.begin());
  // Golden section on [best − 1°, best + 1°].
  double a = deg[best] - 1, b = deg[best] + 1;
  const double g = (std::sqrt(5.0) - 1) / 2;
  int64_t n = 0;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = spread_at(pts, light, floor, x1, &n), f2 = spread_at(pts, light, floor, x2, &n);
  while (b - a > 0.05) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = spread_at(pts, light, floor, x1, &n);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = spread_at(pts, light, floor, x2, &n);
    }
  }
  const double refined = 0.5 * (a + b);
  const double fr = spread_at(pts, light, floor, refined, &n);
  int64_t nb = 0;
  const double fb = spread_at(pts, light, floor, deg[best], &nb);  // the coarse best, on all the points
  if (fr <= fb && n >= kMinMatchPoints) {
    f.yaw_deg = refined, f.spread = fr, f.points = n;
  } else {
    f.yaw_deg = deg[best], f.spread = fb, f.points = nb;
  }
  f.runner_up_spread = 1e300;
  for (size_t i = 0; i < deg.size(); ++i) {
    double dd = std::abs(deg[i] - f.yaw_deg);
    dd = std::min(dd, 360 - dd);
    if (dd > 20 && val[i] < f.runner_up_spread) f.runner_up_spread = val[i], f.runner_up_deg = deg[i];
  }
  if (f.runner_up_spread < 1e300) {  // on all the points, as the others
    int64_t nr = 0;
    f.runner_up_spread = spread_at(pts, light, floor, f.runner_up_deg, &nr);
  }
  f.yaw_deg = std::remainder(f.yaw_deg, 360.0);  // in [−180°, 180°]
  f.valid = f.spread < 1e300;
  return f;
}

PositionFit register_position(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                              const LocalRadiance& light, double saturated, double range_m, double yaw_deg) {
  if (!(range_m > 0 && range_m <= 5))
    fail(ErrorKind::Value, "register: position range {} m must lie in (0, 5]", range_m);
  if (!std::isfinite(yaw_deg)) fail(ErrorKind::Value, "register: turn {}° is not a number", yaw_deg);
  const Seen seen = seen_for(photo, cam, proxy, light, saturated, 5000, yaw_deg);
  PositionFit f;
  f.spread_given = seen.given;
  f.points = seen.given_points;
  if (f.points < kMinMatchPoints) return f;
  const std::vector<SeenPoint>&pts = seen.all, &some = seen.some;
  // A grid of 11³ offsets over ±range on the few points, then twice a 5³ grid a quarter as fine around the best,
  // the last on all of them (steps range/5, /20, /80: 4 cm, 1 cm, 2.5 mm for the default 0.2 m).
  Vec3 best{0, 0, 0};
  double step = range_m / 5, best_v = 1e300;
  for (int level = 0; level < 3; ++level) {
    const int k = level == 0 ? 5 : 2;
    const std::vector<SeenPoint>& use = level == 2 ? pts : some;
    const int64_t need = level == 2 ? kMinMatchPoints : seen.min_some;
    const int side = 2 * k + 1;
    std::vector<double> val(static_cast<size_t>(side) * side * side);
    const Vec3 around = best;
    parallel_for(0, static_cast<int64_t>(val.size()), [&](int64_t i) {
      const int a = static_cast<int>(i % side) - k, b = static_cast<int>(i / side % side) - k,
                c = static_cast<int>(i / side / side) - k;
      const Vec3 o = around + Vec3{a * step, b * step, c * step};
      int64_t n = 0;
      const double v =
          length(o) <= range_m * std::sqrt(3.0) + 1e-12 ? spread_at(use, light, seen.floor, yaw_deg, &n, o) : 1e300;
      val[static_cast<size_t>(i)] = n >= need ? v : 1e300;
    });
    const size_t at = static_cast<size_t>(std::min_element(val.begin(), val.end()) - val.begin());
    best_v = val[at];
    best = around + Vec3{(static_cast<int>(at % side) - k) * step, (static_cast<int>(at / side % side) - k) * step,
                         (static_cast<int>(at / side / side) - k) * step};
    step /= 4;
  }
  int64_t n = 0;
  f.spread = spread_at(pts, light, seen.floor, yaw_deg, &n, best);
  f.offset = best;
  f.points = n;
  if (!(f.spread < f.spread_given))
    f.offset = {0, 0, 0}, f.spread = f.spread_given, f.points = seen.given_points;  // as given
  f.valid = best_v < 1e300 && f.spread < 1e300;
  return f;
}

LocalRadiance turned(const LocalRadiance& light, double yaw_deg) {
  if (!std::isfinite(yaw_deg)) fail(ErrorKind::Value, "turn {}° is not a number", yaw_deg);
  LocalRadiance out = light;
  const sphere::Mapping& m = light.map.mapping;
  Image& img = out.map.image;
  const int W = img.width(), H = img.height(), C = img.channels();
  const bool depth = !light.depth.empty();
  parallel_for(0, H, [&](int64_t y) {
    std::vector<float> v(static_cast<size_t>(C));
    for (int x = 0; x < W; ++x) {
      Vec3 d;
      if (!m.to_direction(x + 0.5, static_cast<double>(y) + 0.5, &d)) continue;
      const Vec3 src = turn_y(d, -yaw_deg);
      light.map.sample(src, v.data());
      for (int c = 0; c < C; ++c) img.at(x, static_cast<int>(y), c) = v[static_cast<size_t>(c)];
      if (depth) {
        double px, py;
        if (m.to_pixel(src, &px, &py))
          out.depth.at(x, static_cast<int>(y), 0) =
              light.depth.at(std::clamp(static_cast<int>(px), 0, light.depth.width() - 1),
                             std::clamp(static_cast<int>(py), 0, light.depth.height() - 1), 0);
      }
    }
  });
  return out;
}

}  // namespace ibl::augment
