// Small fixed-size vectors and 3x3 frames. World convention (docs/conventions.md):
// right-handed, +Y up, metres.
#pragma once
#include <algorithm>
#include <cmath>

namespace ibl {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kFourPi = 4.0 * kPi;

struct Vec2 {
  double x = 0, y = 0;
  constexpr Vec2() = default;
  constexpr Vec2(double x_, double y_) : x(x_), y(y_) {}
  constexpr Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2 operator*(double s) const { return {x * s, y * s}; }
};

struct Vec3 {
  double x = 0, y = 0, z = 0;
  constexpr Vec3() = default;
  constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3 operator+(Vec3 o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(Vec3 o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3 operator*(Vec3 o) const { return {x * o.x, y * o.y, z * o.z}; }
  Vec3& operator+=(Vec3 o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  Vec3& operator-=(Vec3 o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  Vec3& operator*=(double s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
};
constexpr Vec3 operator*(double s, Vec3 v) { return v * s; }
constexpr double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double length(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(Vec3 a) {
  double l = length(a);
  return l > 0 ? a / l : Vec3{0, 0, 0};
}
inline double max_component(Vec3 a) { return std::max({a.x, a.y, a.z}); }

// Luminance of linear Rec.709 RGB (docs/conventions.md).
inline constexpr double kLumR = 0.2125, kLumG = 0.7154, kLumB = 0.0721;
constexpr double luminance(double r, double g, double b) { return kLumR * r + kLumG * g + kLumB * b; }
constexpr double luminance(Vec3 rgb) { return luminance(rgb.x, rgb.y, rgb.z); }

// Row-major 3x3 matrix; used as a rotation (probe frame -> world, etc.).
struct Mat3 {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  static Mat3 identity() { return {}; }
  static Mat3 rows(Vec3 a, Vec3 b, Vec3 c) {
    Mat3 r;
    for (int j = 0; j < 3; ++j) {
      r.m[0][j] = a[j];
      r.m[1][j] = b[j];
      r.m[2][j] = c[j];
    }
    return r;
  }
  // Rotation by `angle` radians about unit `axis` (right-hand rule).
  static Mat3 rotation(Vec3 axis, double angle) {
    Vec3 a = normalize(axis);
    double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    Mat3 r;
    r.m[0][0] = t * a.x * a.x + c;
    r.m[0][1] = t * a.x * a.y - s * a.z;
    r.m[0][2] = t * a.x * a.z + s * a.y;
    r.m[1][0] = t * a.x * a.y + s * a.z;
    r.m[1][1] = t * a.y * a.y + c;
    r.m[1][2] = t * a.y * a.z - s * a.x;
    r.m[2][0] = t * a.x * a.z - s * a.y;
    r.m[2][1] = t * a.y * a.z + s * a.x;
    r.m[2][2] = t * a.z * a.z + c;
    return r;
  }
  Vec3 operator*(Vec3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  Mat3 operator*(const Mat3& o) const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.m[i][j] = m[i][0] * o.m[0][j] + m[i][1] * o.m[1][j] + m[i][2] * o.m[2][j];
    return r;
  }
  Mat3 transposed() const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.m[i][j] = m[j][i];
    return r;
  }
};

// Orthonormal frame around a unit normal (Duff et al. 2017, "Building an orthonormal basis, revisited").
struct Frame {
  Vec3 t, b, n;
  static Frame from_normal(Vec3 n) {
    double sign = std::copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z), bb = n.x * n.y * a;
    return {{1 + sign * n.x * n.x * a, sign * bb, -sign * n.x}, {bb, sign + n.y * n.y * a, -n.y}, n};
  }
  Vec3 to_local(Vec3 v) const { return {dot(v, t), dot(v, b), dot(v, n)}; }
  Vec3 from_local(Vec3 v) const { return t * v.x + b * v.y + n * v.z; }
};

}  // namespace ibl
