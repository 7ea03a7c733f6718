#include "iblkit/sphere/pointset.h"

#include <array>
#include <cmath>
#include <map>

#include "iblkit/core/error.h"

namespace ibl::sphere {

namespace {

struct Mesh {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> f;
};

Mesh icosahedron() {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;  // golden ratio
  Mesh m;
  m.v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : m.v) p = normalize(p);
  m.f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return m;
}

Mesh subdivide(int level) {
  if (level < 0 || level > 9) fail(ErrorKind::Value, "icosphere level {} is outside [0, 9]", level);
  Mesh m = icosahedron();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.v.push_back(normalize(m.v[a] + m.v[b]));
      return mid[key] = static_cast<int>(m.v.size()) - 1;
    };
    std::vector<std::array<int, 3>> nf;
    nf.reserve(m.f.size() * 4);
    for (auto [a, b, c] : m.f) {
      int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      nf.push_back({a, ab, ca});
      nf.push_back({b, bc, ab});
      nf.push_back({c, ca, bc});
      nf.push_back({ab, bc, ca});
    }
    m.f = std::move(nf);
  }
  return m;
}

}  // namespace

std::vector<Vec3> icosphere_face_centres(int level) {
  Mesh m = subdivide(level);
  std::vector<Vec3> out;
  out.reserve(m.f.size());
  for (auto [a, b, c] : m.f) out.push_back(normalize(m.v[a] + m.v[b] + m.v[c]));
  return out;
}

std::vector<Vec3> icosphere_vertices(int level) { return subdivide(level).v; }

std::vector<Vec3> fibonacci_sphere(int n) {
  if (n < 1) fail(ErrorKind::Value, "Fibonacci sphere needs at least 1 point (got {})", n);
  std::vector<Vec3> out(n);
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));  // 2π(1 − 1/φ)
  for (int i = 0; i < n; ++i) {
    double y = 1.0 - (2.0 * i + 1.0) / n;
    double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    double phi = golden_angle * i;
    out[i] = {r * std::cos(phi), y, r * std::sin(phi)};
  }
  return out;
}

}  // namespace ibl::sphere
