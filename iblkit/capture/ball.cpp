#include "iblkit/capture/ball.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/ilf/ball.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::capture {

Conductor chrome() { return {{3.1, 3.1, 3.1}, {3.3, 3.3, 3.3}}; }
Conductor steel() { return {{2.9, 2.9, 2.9}, {3.0, 3.0, 3.0}}; }

namespace {
double fresnel1(double n, double k, double c) {
  c = std::clamp(c, 0.0, 1.0);
  const double c2 = c * c, s2 = 1 - c2;
  const double t0 = n * n - k * k - s2;
  const double ab = std::sqrt(t0 * t0 + 4 * n * n * k * k);  // a² + b²
  const double a = std::sqrt(std::max(0.0, 0.5 * (ab + t0)));
  const double t1 = ab + c2, t2 = 2 * a * c;
  const double rs = (t1 - t2) / (t1 + t2);
  const double t3 = c2 * ab + s2 * s2, t4 = t2 * s2;
  const double rp = rs * (t3 - t4) / (t3 + t4);
  return 0.5 * (rs + rp);
}
}  // namespace

Vec3 fresnel_conductor(const Conductor& m, double c) {
  return {fresnel1(m.n.x, m.k.x, c), fresnel1(m.n.y, m.k.y, c), fresnel1(m.n.z, m.k.z, c)};
}

Vec3 BallReflectance::at(double cos_theta) const {
  if (!fresnel) return r0 ? *r0 : fresnel_conductor(metal, 1.0);
  Vec3 f = fresnel_conductor(metal, cos_theta);
  if (!r0) return f;
  Vec3 f0 = fresnel_conductor(metal, 1.0);
  return {r0->x * f.x / f0.x, r0->y * f.y / f0.y, r0->z * f.z / f0.z};
}

void parse_fresnel(const std::string& s, BallReflectance* r, const std::string& what) {
  if (s == "chrome") {
    r->metal = chrome();
    r->fresnel = true;
  } else if (s == "steel") {
    r->metal = steel();
    r->fresnel = true;
  } else if (s == "none") {
    r->fresnel = false;
  } else {
    double n = 0, k = 0;
    char comma = 0;
    std::istringstream in(s);
    if (!(in >> n >> comma >> k) || comma != ',' || !(n > 0) || !(k >= 0) || !std::isfinite(n) || !std::isfinite(k))
      fail(ErrorKind::Value, "{}: expected chrome, steel, none or n,k (n > 0, k ≥ 0), got \"{}\"", what, s);
    r->metal = {{n, n, n}, {k, k, k}};
    r->fresnel = true;
  }
}

double distance_from_lens(double radius_px, int image_width, double focal_mm, double sensor_mm) {
  if (!(focal_mm > 0 && sensor_mm > 0 && std::isfinite(focal_mm) && std::isfinite(sensor_mm)))
    fail(ErrorKind::Value, "--focal-mm {} and --sensor-mm {} must both be positive", focal_mm, sensor_mm);
  if (!(radius_px > 0)) fail(ErrorKind::Value, "ball radius {} px must be positive", radius_px);
  double f_px = focal_mm / sensor_mm * image_width;
  return 1.0 / std::sin(std::atan(radius_px / f_px));
}

sphere::Mapping output_mapping(sphere::MappingKind k, int size) {
  if (size < 1 || size > 16384) fail(ErrorKind::Value, "output size {} is out of range [1, 16384] (--size)", size);
  using K = sphere::MappingKind;
  switch (k) {
    case K::LatLong:
      return {k, 2 * size, size};
    case K::CubeHCross:
      return {k, 4 * size, 3 * size};
    case K::CubeVCross:
      return {k, 3 * size, 4 * size};
    case K::CubeStrip:
      return {k, 6 * size, size};
    default:
      return {k, size, size};
  }
}

// ---- finding the ball -----------------------------------------------------------------------------

CircleFit find_ball(const Image& photo, const std::string& file, const std::string& option) {
  const int W = photo.width(), H = photo.height();
  auto say = [&](const std::string& why) -> void {
    fail(ErrorKind::Value, "{}: no chrome ball found ({}); give it with {} cx,cy,r (pixels)", file, why, option);
  };
  if (W < 16 || H < 16 || photo.channels() < 1) say("the image is smaller than 16×16");
  // Log luminance (a ball's edge is a step in any exposure), Sobel gradient magnitude.
  Image L(W, H, 1);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double v = photo.channels() >= 3 ? luminance(photo.rgb(x, y)) : photo.at(x, y, 0);
      L.at(x, y, 0) = static_cast<float>(std::log(std::max(v, 0.0) + 1e-4));
    }
  struct Edge {
    double x, y, g;
  };
  std::vector<Edge> edges;
  for (int y = 1; y < H - 1; ++y)
    for (int x = 1; x < W - 1; ++x) {
      auto l = [&](int dx, int dy) { return double(L.at(x + dx, y + dy, 0)); };
      double gx = (l(1, -1) + 2 * l(1, 0) + l(1, 1)) - (l(-1, -1) + 2 * l(-1, 0) + l(-1, 1));
      double gy = (l(-1, 1) + 2 * l(0, 1) + l(1, 1)) - (l(-1, -1) + 2 * l(0, -1) + l(1, -1));
      double g = std::hypot(gx, gy);
      // Keep local maxima along the gradient (thin edges).
      if (g <= 0) continue;
      int sx = static_cast<int>(std::lround(gx / g)), sy = static_cast<int>(std::lround(gy / g));
      auto gm = [&](int xx, int yy) {
        if (xx < 1 || yy < 1 || xx >= W - 1 || yy >= H - 1) return 0.0;
        auto ll = [&](int dx, int dy) { return double(L.at(xx + dx, yy + dy, 0)); };
        double ax = (ll(1, -1) + 2 * ll(1, 0) + ll(1, 1)) - (ll(-1, -1) + 2 * ll(-1, 0) + ll(-1, 1));
        double ay = (ll(-1, 1) + 2 * ll(0, 1) + ll(1, 1)) - (ll(-1, -1) + 2 * ll(0, -1) + ll(1, -1));
        return std::hypot(ax, ay);
      };
      const double gp = gm(x + sx, y + sy), gn = gm(x - sx, y - sy);
      if (g < gp || g < gn) continue;
      // Sub-pixel: the peak of the parabola through the three magnitudes along the gradient's step.
      const double curv = gn - 2 * g + gp, t = curv < 0 ? std::clamp(0.5 * (gn - gp) / curv, -0.5, 0.5) : 0.0;
      edges.push_back({x + 0.5 + t * sx, y + 0.5 + t * sy, g});  // t in units of the step (sx, sy)
    }
  if (edges.size() < 16) say("too few edges");
  // The strongest 12 · (W + H) edge points: a ball's outline is a long edge, if not the strongest one.
  size_t keep = std::min(edges.size(), static_cast<size_t>(12 * (W + H)));
  std::nth_element(edges.begin(), edges.begin() + (keep - 1), edges.end(),
                   [](const Edge& a, const Edge& b) { return a.g > b.g; });
  edges.resize(keep);
  const double tol = std::max(1.0, 0.004 * std::min(W, H));
  auto circle3 = [](const Edge& a, const Edge& b, const Edge& c, BallCircle* out) {
    double bx = b.x - a.x, by = b.y - a.y, cx = c.x - a.x, cy = c.y - a.y;
    double d = 2 * (bx * cy - by * cx);
    if (std::abs(d) < 1e-9) return false;
    double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
    *out = {a.x + ux, a.y + uy, std::hypot(ux, uy)};
    return true;
  };
  auto coverage = [&](const BallCircle& c, std::vector<int>* inl) {
    std::vector<char> bins(360, 0);
    inl->clear();
    for (size_t i = 0; i < edges.size(); ++i) {
      double dx = edges[i].x - c.cx, dy = edges[i].y - c.cy;
      if (std::abs(std::hypot(dx, dy) - c.r) > tol) continue;
      inl->push_back(static_cast<int>(i));
      int b = static_cast<int>((std::atan2(dy, dx) + kPi) / (2 * kPi) * 360) % 360;
      bins[b] = 1;
    }
    return std::count(bins.begin(), bins.end(), 1) / 360.0;
  };
  // Candidates drawn in a fixed order, scored in parallel (the best by coverage, ties to the first).
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<size_t> pick(0, edges.size() - 1);
  const double rmin = 8, rmax = 0.5 * std::max(W, H);
  std::vector<BallCircle> cand;
  for (int it = 0; it < 4000; ++it) {
    BallCircle c;
    if (!circle3(edges[pick(rng)], edges[pick(rng)], edges[pick(rng)], &c)) continue;
    if (c.r < rmin || c.r > rmax) continue;
    cand.push_back(c);
  }
  std::vector<double> score(cand.size(), 0);
  BallCircle best;
  double best_cov = 0;
  std::vector<int> inl;
  // In chunks of 256, stopping once a circle has edges along 90 % of its outline.
  for (size_t start = 0; start < cand.size() && best_cov < 0.9; start += 256) {
    const size_t end = std::min(cand.size(), start + 256);
    parallel_for(
        static_cast<int64_t>(start), static_cast<int64_t>(end),
        [&](int64_t i) {
          const BallCircle& c = cand[static_cast<size_t>(i)];
          const double lo = std::max(0.0, c.r - tol), hi = c.r + tol, lo2 = lo * lo, hi2 = hi * hi;
          std::vector<char> bins(360, 0);
          for (const Edge& e : edges) {
            double dx = e.x - c.cx, dy = e.y - c.cy, d2 = dx * dx + dy * dy;
            if (d2 < lo2 || d2 > hi2) continue;
            bins[static_cast<int>((std::atan2(dy, dx) + kPi) / (2 * kPi) * 360) % 360] = 1;
          }
          score[static_cast<size_t>(i)] = std::count(bins.begin(), bins.end(), 1) / 360.0;
        },
        16);
    for (size_t i = start; i < end; ++i)
      if (score[i] > best_cov) best_cov = score[i], best = cand[i];
  }
  if (best_cov < 0.5)
    say(fmt::format("the best circle covers {:.0f} % of its outline with edges, need 50 %", 100 * best_cov));
  // Least squares (Kåsa's algebraic fit, then geometric Gauss-Newton steps) on the inliers.
  BallCircle c = best;
  for (int round = 0; round < 3; ++round) {
    coverage(c, &inl);
    for (int gn = 0; gn < 10; ++gn) {
      double JtJ[3][3] = {}, Jtr[3] = {};
      for (int i : inl) {
        double dx = edges[i].x - c.cx, dy = edges[i].y - c.cy, rr = std::hypot(dx, dy);
        if (rr < 1e-9) continue;
        double J[3] = {-dx / rr, -dy / rr, -1}, res = rr - c.r;
        for (int a = 0; a < 3; ++a) {
          Jtr[a] += J[a] * res;
          for (int b = 0; b < 3; ++b) JtJ[a][b] += J[a] * J[b];
        }
      }
      // Solve JtJ · δ = −Jtr (3×3, Cramer).
      auto det3 = [](double m[3][3]) {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
      };
      double D = det3(JtJ);
      if (std::abs(D) < 1e-12) break;
      double delta[3];
      for (int col = 0; col < 3; ++col) {
        double M[3][3];
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) M[a][b] = b == col ? -Jtr[a] : JtJ[a][b];
        delta[col] = det3(M) / D;
      }
      c.cx += delta[0];
      c.cy += delta[1];
      c.r += delta[2];
      if (std::abs(delta[0]) + std::abs(delta[1]) + std::abs(delta[2]) < 1e-6) break;
    }
  }
  CircleFit fit;
  fit.coverage = coverage(c, &inl);
  fit.circle = c;
  fit.edge_points = static_cast<int>(inl.size());
  double ss = 0;
  for (int i : inl) {
    double e = std::hypot(edges[i].x - c.cx, edges[i].y - c.cy) - c.r;
    ss += e * e;
  }
  fit.residual_px = inl.empty() ? 0 : std::sqrt(ss / inl.size());
  if (c.cx - c.r < 0 || c.cy - c.r < 0 || c.cx + c.r > W || c.cy + c.r > H)
    fail(
        ErrorKind::Value,
        "{}: the ball found at ({:.1f}, {:.1f}), r = {:.1f} px is partly outside the frame; reframe it or give it with "
        "{} cx,cy,r",
        file, c.cx, c.cy, c.r, option);
  return fit;
}

// ---- unwarping ------------------------------------------------------------------------------------

FromBallResult probe_from_ball(const std::vector<BallView>& views, const FromBallDesc& desc) {
  if (views.empty() || views.size() > 2)
    fail(ErrorKind::Value, "probe from a ball: give one or two photographs, got {}", views.size());
  if (desc.samples < 1 || desc.samples > 16)
    fail(ErrorKind::Value, "samples per pixel axis {} is out of range [1, 16] (--samples)", desc.samples);
  if (desc.reflectance.r0) {
    Vec3 r = *desc.reflectance.r0;
    if (!(r.x > 0 && r.x <= 1 && r.y > 0 && r.y <= 1 && r.z > 0 && r.z <= 1))
      fail(ErrorKind::Value, "--reflectance ({}, {}, {}) must lie in (0, 1]", r.x, r.y, r.z);
  }
  if (!(desc.exclude_deg >= 0 && desc.ramp_deg >= 0 && desc.exclude_deg + desc.ramp_deg < 90))
    fail(ErrorKind::Value, "--exclude {}° and its ramp {}° must be ≥ 0 with a sum below 90°", desc.exclude_deg,
         desc.ramp_deg);
  struct Prepared {
    const BallView* v;
    ilf::BallOptics optics;
    Mat3 to_view;  // probe (view 0) frame -> this view's frame
  };
  std::vector<Prepared> P;
  for (const BallView& v : views) {
    const std::string& name = v.name.empty() ? std::string("the photograph") : v.name;
    if (v.photo.channels() < 3)
      fail(ErrorKind::Value, "{}: {} channels; a ball photograph needs RGB", name, v.photo.channels());
    if (!(v.ball.r > 0) || !std::isfinite(v.ball.cx) || !std::isfinite(v.ball.cy) || !std::isfinite(v.ball.r))
      fail(ErrorKind::Value, "{}: ball radius {} px must be positive (--ball cx,cy,r)", name, v.ball.r);
    if (v.ball.cx - v.ball.r < -0.5 || v.ball.cy - v.ball.r < -0.5 || v.ball.cx + v.ball.r > v.photo.width() + 0.5 ||
        v.ball.cy + v.ball.r > v.photo.height() + 0.5)
      fail(ErrorKind::Value, "{}: the ball ({}, {}), r = {} is partly outside the {}×{} frame (--ball)", name,
           v.ball.cx, v.ball.cy, v.ball.r, v.photo.width(), v.photo.height());
    if (v.distance != 0 && !(v.distance > 1 && std::isfinite(v.distance)))
      fail(ErrorKind::Value, "{}: camera distance {} ball radii must exceed 1 (--distance; 0: orthographic)", name,
           v.distance);
    Prepared p{&v, {}, Mat3::rotation({0, 1, 0}, v.angle_deg * kPi / 180).transposed()};
    if (v.distance > 0) p.optics = {1.0, v.distance};
    P.push_back(p);
  }
  FromBallResult res;
  const sphere::Mapping m = output_mapping(desc.mapping, desc.size);
  const int W = m.width(), H = m.height(), n = desc.samples;
  Image out(W, H, 4), weights(W, H, 1);
  const Mat3 Rt = desc.rotation.transposed();
  const double s_lo = std::sin(desc.exclude_deg * kPi / 180),
               s_hi = std::sin((desc.exclude_deg + desc.ramp_deg) * kPi / 180);
  const bool two = P.size() == 2;
  std::vector<int64_t> invalid_rows(H, 0);
  parallel_for(0, H, [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < W; ++x) {
      Vec3 sum;
      double alpha = 0, share = 0;
      int used = 0;
      for (int s = 0; s < n * n; ++s) {
        Vec3 d;
        if (!m.to_direction(x + (s % n + 0.5) / n, y + (s / n + 0.5) / n, &d)) continue;
        ++used;
        d = Rt * d;
        Vec3 val[2];
        double w[2] = {0, 0}, axis_sin[2] = {0, 0};
        bool ok[2] = {false, false};
        for (size_t k = 0; k < P.size(); ++k) {
          Vec3 dv = P[k].to_view * d, view, nrm;
          if (!ilf::ball_view_for(P[k].optics, dv, &view, &nrm)) continue;
          const BallView& bv = *P[k].v;
          double px, py;
          ilf::ball_image_point(P[k].optics, view, nrm, bv.ball.cx, bv.ball.cy, bv.ball.r, &px, &py);
          float rgb[4] = {0, 0, 0, 0};
          bv.photo.view().bilinear(px, py, Wrap::Clamp, rgb);
          Vec3 R = desc.reflectance.at(-dot(view, nrm));
          val[k] = {rgb[0] / R.x, rgb[1] / R.y, rgb[2] / R.z};
          ok[k] = true;
          axis_sin[k] = std::sqrt(std::max(0.0, 1 - dv.z * dv.z));
          w[k] = s_hi > s_lo ? std::clamp((axis_sin[k] - s_lo) / (s_hi - s_lo), 0.0, 1.0) : axis_sin[k] >= s_lo;
        }
        if (!ok[0] && !(two && ok[1])) continue;
        alpha += 1;
        if (!two) {
          sum += val[0];
          share += 1;
          continue;
        }
        if (w[0] + w[1] <= 0) {  // both in their excluded cones: the view farther from its axis
          int k = (ok[0] && (!ok[1] || axis_sin[0] >= axis_sin[1])) ? 0 : 1;
          w[k] = 1;
          w[1 - k] = 0;
        }
        if (!ok[0]) w[0] = 0;
        if (!ok[1]) w[1] = 0;
        double ws = w[0] + w[1];
        sum += (val[0] * w[0] + val[1] * w[1]) / ws;
        share += w[0] / ws;
      }
      if (used == 0) continue;
      if (alpha > 0) out.set_rgb(x, y, sum / alpha);
      out.at(x, y, 3) = static_cast<float>(alpha / used);
      weights.at(x, y, 0) = static_cast<float>(alpha > 0 ? share / alpha : 0.0);
      if (alpha == 0) ++invalid_rows[y];
    }
  });
  for (int64_t c : invalid_rows) res.invalid_pixels += c;
  if (!two && P[0].optics.distance > 0) res.blind_cone_deg = std::asin(1.0 / P[0].optics.distance) * 180 / kPi;
  res.probe = sphere::EnvMap(std::move(out), m);
  res.weights = std::move(weights);
  return res;
}

AngleEstimate estimate_angle(const std::vector<BallView>& views, const FromBallDesc& desc, double lo_deg,
                             double hi_deg) {
  if (views.size() != 2) fail(ErrorKind::Value, "estimating the angle needs two photographs, got {}", views.size());
  if (!(lo_deg < hi_deg)) fail(ErrorKind::Value, "angle search range [{}, {}] is empty", lo_deg, hi_deg);
  const std::vector<Vec3> dirs = sphere::fibonacci_sphere(2048);
  const double s_full = std::sin((desc.exclude_deg + desc.ramp_deg) * kPi / 180);
  // Log luminance of a view along direction dv (its own frame), or false where it is not trusted.
  auto sample = [&](const BallView& v, Vec3 dv, double* out) {
    if (std::sqrt(std::max(0.0, 1 - dv.z * dv.z)) < s_full) return false;
    ilf::BallOptics o = v.distance > 0 ? ilf::BallOptics{1.0, v.distance} : ilf::BallOptics{};
    Vec3 view, nrm;
    if (!ilf::ball_view_for(o, dv, &view, &nrm)) return false;
    double px, py;
    ilf::ball_image_point(o, view, nrm, v.ball.cx, v.ball.cy, v.ball.r, &px, &py);
    float rgb[4] = {0, 0, 0, 0};
    v.photo.view().bilinear(px, py, Wrap::Clamp, rgb);
    Vec3 R = desc.reflectance.at(-dot(view, nrm));
    *out = luminance(rgb[0] / R.x, rgb[1] / R.y, rgb[2] / R.z);
    return true;
  };
  std::vector<double> first(dirs.size());
  std::vector<char> first_ok(dirs.size());
  std::vector<double> seen;
  for (size_t i = 0; i < dirs.size(); ++i)
    if ((first_ok[i] = sample(views[0], dirs[i], &first[i]))) seen.push_back(first[i]);
  if (seen.empty()) fail(ErrorKind::Value, "the first view sees nothing to register; give the angle with --angle");
  // Dark directions (below 1 % of the median) are noise: they count at that floor.
  std::nth_element(seen.begin(), seen.begin() + seen.size() / 2, seen.end());
  const double floor = std::max(1e-12, 0.01 * seen[seen.size() / 2]);
  for (double& v : first) v = std::log(std::max(v, floor));
  auto cost = [&](double angle, int* count) {
    const Mat3 to_view = Mat3::rotation({0, 1, 0}, angle * kPi / 180).transposed();
    double ss = 0;
    int n = 0;
    for (size_t i = 0; i < dirs.size(); ++i) {
      double b;
      if (!first_ok[i] || !sample(views[1], to_view * dirs[i], &b)) continue;
      b = std::log(std::max(b, floor));
      ss += std::abs(first[i] - b);
      ++n;
    }
    if (count) *count = n;
    return n >= 32 ? ss / n : std::numeric_limits<double>::infinity();
  };
  double best = lo_deg, best_c = std::numeric_limits<double>::infinity();
  for (double a = lo_deg; a <= hi_deg + 1e-9; a += 1) {
    double c = cost(a, nullptr);
    if (c < best_c) best_c = c, best = a;
  }
  if (!std::isfinite(best_c))
    fail(ErrorKind::Value, "the two views share no directions to register; give the angle with --angle");
  double a = best - 1, b = best + 1;
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = cost(x1, nullptr), f2 = cost(x2, nullptr);
  while (b - a > 0.01) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = cost(x1, nullptr);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = cost(x2, nullptr);
    }
  }
  AngleEstimate e;
  e.angle_deg = 0.5 * (a + b);
  e.residual = cost(e.angle_deg, &e.directions);
  return e;
}

}  // namespace ibl::capture
