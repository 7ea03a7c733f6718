#include "iblkit/ilf/ball.h"

#include <cmath>

namespace ibl::ilf {

bool ball_ray(const BallOptics& o, int width, int height, double px, double py, Vec3* start, Vec3* dir) {
  double a = 2 * px / width - 1, b = 1 - 2 * py / height, r2 = a * a + b * b;
  if (r2 >= 1) return false;
  double r = std::max(o.radius, 0.0);
  if (!(o.distance > r) || r <= 0) {  // orthographic (a perspective camera needs a radius below its distance)
    Vec3 n{a, b, std::sqrt(1 - r2)};
    *start = n * r;
    *dir = Vec3{0, 0, -1} + n * (2 * n.z);
    return true;
  }
  double D = o.distance, tan_a = r / std::sqrt(D * D - r * r);
  Vec3 v = normalize(Vec3{a * tan_a, b * tan_a, -1});
  if (!ball_reflect(o, v, start, dir)) {  // on the silhouette to rounding: the grazing ray
    Vec3 C{0, 0, D};
    Vec3 n = normalize(C - v * dot(C, v));
    *start = n * r;
    *dir = v;
  }
  return true;
}

bool ball_reflect(const BallOptics& o, Vec3 v, Vec3* start, Vec3* dir) {
  const double r = o.radius, D = o.distance;
  if (!(r > 0 && D > r)) return false;
  Vec3 C{0, 0, D};
  double cv = dot(C, v), disc = cv * cv - (D * D - r * r);
  if (disc < 0 || cv >= 0) return false;
  double t = -cv - std::sqrt(disc);
  Vec3 n = normalize((C + v * t) / r);
  *start = n * r;
  *dir = normalize(v - n * (2 * dot(v, n)));
  return true;
}

bool ball_view_for(const BallOptics& o, Vec3 d, Vec3* view, Vec3* normal) {
  const double r = o.radius, D = o.distance;
  if (!(r > 0 && D > r)) {  // orthographic: n bisects +Z and d
    Vec3 h = d + Vec3{0, 0, 1};
    if (length(h) < 1e-12) return false;
    *normal = normalize(h);
    *view = {0, 0, -1};
    return true;
  }
  // In the plane of +Z and d: e the unit in-plane axis perpendicular to Z, psi the target angle of d
  // from +Z; the normal n(φ) = sin φ e + cos φ z, φ ∈ [0, acos(r/D)] (centre to silhouette).
  const double rho = std::sqrt(d.x * d.x + d.y * d.y), psi = std::atan2(rho, d.z);
  const double alpha = std::asin(r / D), phi_max = std::acos(r / D);
  if (psi >= kPi - alpha) return false;  // behind the ball
  Vec3 e = rho > 1e-15 ? Vec3{d.x / rho, d.y / rho, 0} : Vec3{1, 0, 0};
  auto reflected_angle = [&](double phi, Vec3* v, Vec3* n) {
    *n = e * std::sin(phi) + Vec3{0, 0, std::cos(phi)};
    *v = normalize(*n * r - Vec3{0, 0, D});
    Vec3 out = *v - *n * (2 * dot(*v, *n));
    return std::atan2(dot(out, e), out.z);
  };
  double lo = 0, hi = phi_max;
  Vec3 v, n;
  for (int i = 0; i < 60 && hi - lo > 1e-12; ++i) {
    double mid = 0.5 * (lo + hi);
    (reflected_angle(mid, &v, &n) < psi ? lo : hi) = mid;
  }
  reflected_angle(0.5 * (lo + hi), &v, &n);
  *view = v;
  *normal = n;
  return true;
}

void ball_image_point(const BallOptics& o, Vec3 view, Vec3 normal, double cx, double cy, double r, double* px,
                      double* py) {
  double a, b;
  if (o.radius > 0 && o.distance > o.radius) {
    double tan_a = o.radius / std::sqrt(o.distance * o.distance - o.radius * o.radius);
    a = view.x / (-view.z * tan_a);
    b = view.y / (-view.z * tan_a);
  } else {
    a = normal.x;
    b = normal.y;
  }
  *px = cx + a * r;
  *py = cy - b * r;
}

double ball_pixel_solid_angle(const BallOptics& o, int width, int height, int x, int y, int n) {
  double sum = 0, e = 1e-3;
  Vec3 s, d0, d1, d2, d3;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double px = x + (i + 0.5) / n, py = y + (j + 0.5) / n;
      if (!ball_ray(o, width, height, px, py, &s, &d0)) continue;
      if (!ball_ray(o, width, height, px + e, py, &s, &d0) || !ball_ray(o, width, height, px - e, py, &s, &d1) ||
          !ball_ray(o, width, height, px, py + e, &s, &d2) || !ball_ray(o, width, height, px, py - e, &s, &d3)) {
        // On the rim: one-sided differences toward the inside.
        Vec3 c;
        ball_ray(o, width, height, px, py, &s, &c);
        bool xp = ball_ray(o, width, height, px + e, py, &s, &d0), xm = ball_ray(o, width, height, px - e, py, &s, &d1);
        bool yp = ball_ray(o, width, height, px, py + e, &s, &d2), ym = ball_ray(o, width, height, px, py - e, &s, &d3);
        Vec3 dx = xp ? (d0 - c) / e : xm ? (c - d1) / e : Vec3{0, 0, 0};
        Vec3 dy = yp ? (d2 - c) / e : ym ? (c - d3) / e : Vec3{0, 0, 0};
        sum += length(cross(dx, dy));
        continue;
      }
      sum += length(cross((d0 - d1) / (2 * e), (d2 - d3) / (2 * e)));
    }
  return sum / (double(n) * n);
}

}  // namespace ibl::ilf
