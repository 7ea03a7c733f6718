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
  Vec3 C{0, 0, D};
  double cv = dot(C, v), disc = cv * cv - (D * D - r * r);
  double t = -cv - std::sqrt(std::max(disc, 0.0));
  Vec3 n = normalize((C + v * t) / r);
  *start = n * r;
  *dir = normalize(v - n * (2 * dot(v, n)));
  return true;
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
