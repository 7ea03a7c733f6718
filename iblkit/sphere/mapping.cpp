#include "iblkit/sphere/mapping.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <vector>

#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"

namespace ibl::sphere {

namespace {
// Names first (in enum order), then aliases.
constexpr EnumName<MappingKind> kMappingNames[] = {{MappingKind::LatLong, "latlong"},
                                                   {MappingKind::MirrorBall, "mirrorball"},
                                                   {MappingKind::Angular, "angular"},
                                                   {MappingKind::CubeHCross, "hcross"},
                                                   {MappingKind::CubeVCross, "vcross"},
                                                   {MappingKind::CubeStrip, "cubestrip"},
                                                   {MappingKind::Octahedral, "octahedral"},
                                                   {MappingKind::LatLong, "equirect"},
                                                   {MappingKind::LatLong, "equirectangular"},
                                                   {MappingKind::MirrorBall, "ball"},
                                                   {MappingKind::MirrorBall, "chrome"},
                                                   {MappingKind::Angular, "probe"},
                                                   {MappingKind::Angular, "angularmap"},
                                                   {MappingKind::CubeHCross, "cubecross"},
                                                   {MappingKind::CubeHCross, "cube"},
                                                   {MappingKind::CubeHCross, "horizontal-cross"},
                                                   {MappingKind::CubeVCross, "vertical-cross"},
                                                   {MappingKind::CubeStrip, "strip"},
                                                   {MappingKind::Octahedral, "oct"}};

std::string lower(std::string_view s) {
  std::string n(s);
  for (auto& ch : n) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return n;
}
}  // namespace

std::string mapping_name(MappingKind k) { return name_of(kMappingNames, k); }
std::optional<MappingKind> find_mapping(std::string_view name) { return find_enum(kMappingNames, lower(name)); }
MappingKind parse_mapping(std::string_view name, std::string_view what) {
  if (auto k = find_mapping(name)) return *k;
  return parse_enum(kMappingNames, name, "mapping", what);  // fails, listing the names
}

double Mapping::aspect(MappingKind k) {
  switch (k) {
    case MappingKind::LatLong:
      return 2.0;
    case MappingKind::CubeHCross:
      return 4.0 / 3.0;
    case MappingKind::CubeVCross:
      return 3.0 / 4.0;
    case MappingKind::CubeStrip:
      return 6.0;
    default:
      return 1.0;
  }
}

MappingKind detect_mapping(int width, int height, std::string_view file_name) {
  if (width <= 0 || height <= 0) fail(ErrorKind::Value, "image has no pixels ({}x{})", width, height);
  std::string name(file_name);
  for (auto& ch : name) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  auto has = [&](const char* s) { return name.find(s) != std::string::npos; };
  if (width == 2 * height) return MappingKind::LatLong;
  if (width == height) {
    if (has("angular") || has("_probe")) return MappingKind::Angular;
    if (has("oct")) return MappingKind::Octahedral;
    return MappingKind::MirrorBall;
  }
  if (width * 3 == height * 4) return MappingKind::CubeHCross;
  if (width * 4 == height * 3) return MappingKind::CubeVCross;
  if (width == 6 * height) return MappingKind::CubeStrip;
  fail(ErrorKind::Value,
       "cannot tell the mapping of a {}x{} image{}{}: expected 2:1 (latlong), 1:1 (mirrorball/angular/"
       "octahedral), 4:3 or 3:4 (cube cross) or 6:1 (cube strip); name the mapping",
       width, height, name.empty() ? "" : " ", std::string(file_name));
}

Vec3 cube_face_point(int face, double s, double t) {
  switch (face) {
    case 0:
      return {1, -t, -s};
    case 1:
      return {-1, -t, s};
    case 2:
      return {s, 1, t};
    case 3:
      return {s, -1, -t};
    case 4:
      return {s, -t, 1};
    default:
      return {-s, -t, -1};
  }
}

int cube_face_of(Vec3 d, double* s, double* t) {
  double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  if (ax >= ay && ax >= az) {
    if (d.x > 0) {
      *s = -d.z / ax;
      *t = -d.y / ax;
      return 0;
    }
    *s = d.z / ax;
    *t = -d.y / ax;
    return 1;
  }
  if (ay >= az) {
    if (d.y > 0) {
      *s = d.x / ay;
      *t = d.z / ay;
      return 2;
    }
    *s = d.x / ay;
    *t = -d.z / ay;
    return 3;
  }
  if (d.z > 0) {
    *s = d.x / az;
    *t = -d.y / az;
    return 4;
  }
  *s = -d.x / az;
  *t = -d.y / az;
  return 5;
}

namespace {

// Cells of the cross layouts: (column, row) of each face; vcross turns −Z by 180°.
constexpr std::array<std::array<int, 2>, 6> kHCrossCells = {{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}}};
constexpr std::array<std::array<int, 2>, 6> kVCrossCells = {{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}}};

// ∫ sqrt(1 − x²) dx, the antiderivative used for exact disc areas.
double disc_g(double x) {
  x = std::clamp(x, -1.0, 1.0);
  return 0.5 * (x * std::sqrt(std::max(0.0, 1 - x * x)) + std::asin(x));
}

// Exact area of [x0,x1] × [y0,y1] ∩ unit disc. Between the breakpoints where the half chord
// h(x) = sqrt(1−x²) crosses y0 or y1, the overlap of [y0,y1] with [−h,h] is c0 + c1·h(x).
double rect_disc_area(double x0, double x1, double y0, double y1) {
  std::vector<double> xs = {x0, x1};
  for (double y : {y0, y1})
    if (std::abs(y) <= 1) {  // ≤: an edge on y = ±1 touches the disc at x = 0 (a 1×1 ball had area 4)
      double c = std::sqrt(1 - y * y);
      xs.push_back(c);
      xs.push_back(-c);
    }
  xs.push_back(-1);
  xs.push_back(1);
  std::sort(xs.begin(), xs.end());
  double area = 0;
  for (size_t i = 0; i + 1 < xs.size(); ++i) {
    double a = std::max(xs[i], std::max(x0, -1.0)), b = std::min(xs[i + 1], std::min(x1, 1.0));
    if (b <= a) continue;
    double m = 0.5 * (a + b), h = std::sqrt(std::max(0.0, 1 - m * m));
    bool top_is_h = h<y1, bottom_is_h = -h> y0;
    double top = top_is_h ? h : y1, bottom = bottom_is_h ? -h : y0;
    if (top <= bottom) continue;
    double c1 = (top_is_h ? 1.0 : 0.0) + (bottom_is_h ? 1.0 : 0.0);
    double c0 = (top_is_h ? 0.0 : y1) - (bottom_is_h ? 0.0 : y0);
    area += c0 * (b - a) + c1 * (disc_g(b) - disc_g(a));
  }
  return area;
}

// Solid angle of the cube-face rectangle [s0,s1] × [t0,t1] (face at distance 1).
double cube_rect_solid_angle(double s0, double s1, double t0, double t1) {
  auto f = [](double s, double t) { return std::atan2(s * t, std::sqrt(s * s + t * t + 1)); };
  return f(s1, t1) - f(s0, t1) - f(s1, t0) + f(s0, t0);
}

// Solid angle of triangle (a,b,c) seen from the origin (Van Oosterom & Strackee 1983).
double triangle_solid_angle(Vec3 a, Vec3 b, Vec3 c) {
  double la = length(a), lb = length(b), lc = length(c);
  double num = std::abs(dot(a, cross(b, c)));
  double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

using Poly = std::vector<Vec2>;
// Keeps the part of polygon p where n·q <= c (Sutherland–Hodgman).
Poly clip(const Poly& p, Vec2 n, double c) {
  Poly out;
  for (size_t i = 0; i < p.size(); ++i) {
    Vec2 a = p[i], b = p[(i + 1) % p.size()];
    double da = n.x * a.x + n.y * a.y - c, db = n.x * b.x + n.y * b.y - c;
    if (da <= 0) out.push_back(a);
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      double t = da / (da - db);
      out.push_back(a + (b - a) * t);
    }
  }
  return out;
}

Vec3 oct_point(double a, double b) {
  double y = 1 - std::abs(a) - std::abs(b);
  if (y >= 0) return {a, y, b};
  double sa = a >= 0 ? 1 : -1, sb = b >= 0 ? 1 : -1;
  return {(1 - std::abs(b)) * sa, y, (1 - std::abs(a)) * sb};
}

}  // namespace

Mapping::Mapping(MappingKind kind, int width, int height, double dead_angle_deg)
    : kind_(kind), width_(width), height_(height), dead_angle_deg_(dead_angle_deg) {
  if (width <= 0 || height <= 0) fail(ErrorKind::Value, "mapping size {}x{} is invalid", width, height);
  if (!(dead_angle_deg >= 0 && dead_angle_deg < 90))
    fail(ErrorKind::Value, "dead angle {} deg is outside [0, 90)", dead_angle_deg);
  auto need = [&](bool ok) {
    if (!ok)
      fail(ErrorKind::Value, "a {} image must have aspect {} (got {}x{})", mapping_name(kind), aspect(kind), width,
           height);
  };
  switch (kind) {
    case MappingKind::LatLong:
      break;  // any aspect works; 2:1 gives square pixels at the equator
    case MappingKind::MirrorBall:
    case MappingKind::Angular:
    case MappingKind::Octahedral:
      need(width == height);
      break;
    case MappingKind::CubeHCross:
      need(width % 4 == 0 && height * 4 == width * 3);
      face_ = width / 4;
      break;
    case MappingKind::CubeVCross:
      need(width % 3 == 0 && height * 3 == width * 4);
      face_ = width / 3;
      break;
    case MappingKind::CubeStrip:
      need(width == 6 * height);
      face_ = height;
      break;
  }
  if (kind == MappingKind::MirrorBall && dead_angle_deg > 0) cos_dead_ = std::cos(dead_angle_deg * kPi / 180.0);
}

bool Mapping::cell_face(int cx, int cy, int* face, bool* rot180) const {
  *rot180 = false;
  if (kind_ == MappingKind::CubeStrip) {
    *face = cx;
    return cx >= 0 && cx < 6 && cy == 0;
  }
  const auto& cells = kind_ == MappingKind::CubeHCross ? kHCrossCells : kVCrossCells;
  for (int f = 0; f < 6; ++f)
    if (cells[f][0] == cx && cells[f][1] == cy) {
      *face = f;
      *rot180 = kind_ == MappingKind::CubeVCross && f == 5;
      return true;
    }
  return false;
}

bool Mapping::to_direction(double px, double py, Vec3* d) const {
  switch (kind_) {
    case MappingKind::LatLong: {
      double theta = kPi * py / height_, phi = kTwoPi * px / width_;
      double st = std::sin(theta);
      *d = {-st * std::cos(phi), std::cos(theta), -st * std::sin(phi)};
      return true;
    }
    case MappingKind::MirrorBall: {
      double a = 2 * px / width_ - 1, b = 1 - 2 * py / height_;
      double rho2 = a * a + b * b;
      if (rho2 > 1) return false;
      double nz = std::sqrt(1 - rho2);
      *d = {2 * nz * a, 2 * nz * b, 2 * nz * nz - 1};
      return !(d->z < -cos_dead_);
    }
    case MappingKind::Angular: {
      double a = 2 * px / width_ - 1, b = 1 - 2 * py / height_;
      double r = std::sqrt(a * a + b * b);
      if (r > 1) return false;
      if (r < 1e-300) {
        *d = {0, 0, 1};
        return true;
      }
      double th = kPi * r, s = std::sin(th) / r;
      *d = {s * a, s * b, std::cos(th)};
      return true;
    }
    case MappingKind::Octahedral: {
      double a = 2 * px / width_ - 1, b = 2 * py / height_ - 1;
      *d = normalize(oct_point(a, b));
      return true;
    }
    default: {
      int cx = static_cast<int>(std::floor(px / face_)), cy = static_cast<int>(std::floor(py / face_));
      int face;
      bool rot;
      if (!cell_face(cx, cy, &face, &rot)) return false;
      double s = 2 * (px - cx * face_) / face_ - 1, t = 2 * (py - cy * face_) / face_ - 1;
      if (rot) {
        s = -s;
        t = -t;
      }
      *d = normalize(cube_face_point(face, s, t));
      return true;
    }
  }
}

bool Mapping::to_pixel(Vec3 d, double* px, double* py) const {
  switch (kind_) {
    case MappingKind::LatLong: {
      double u = std::atan2(d.z, d.x) / kTwoPi + 0.5, v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
      *px = u * width_;
      *py = v * height_;
      return true;
    }
    case MappingKind::MirrorBall: {
      Vec3 h{d.x, d.y, d.z + 1};
      double l = length(h);
      double a = l > 1e-300 ? h.x / l : 1.0, b = l > 1e-300 ? h.y / l : 0.0;
      *px = (a + 1) * 0.5 * width_;
      *py = (1 - b) * 0.5 * height_;
      return !(d.z < -cos_dead_);
    }
    case MappingKind::Angular: {
      double th = std::acos(std::clamp(d.z, -1.0, 1.0)), r = th / kPi;
      double s = std::sqrt(d.x * d.x + d.y * d.y);
      double a = s > 1e-300 ? r * d.x / s : r, b = s > 1e-300 ? r * d.y / s : 0.0;
      *px = (a + 1) * 0.5 * width_;
      *py = (1 - b) * 0.5 * height_;
      return true;
    }
    case MappingKind::Octahedral: {
      double n = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
      double x = d.x / n, y = d.y / n, z = d.z / n, a, b;
      if (y >= 0) {
        a = x;
        b = z;
      } else {
        a = (1 - std::abs(z)) * (x >= 0 ? 1 : -1);
        b = (1 - std::abs(x)) * (z >= 0 ? 1 : -1);
      }
      *px = (a + 1) * 0.5 * width_;
      *py = (b + 1) * 0.5 * height_;
      return true;
    }
    default: {
      double s, t;
      int face = cube_face_of(d, &s, &t);
      const auto* cells = kind_ == MappingKind::CubeHCross ? &kHCrossCells : &kVCrossCells;
      int cx = face, cy = 0;
      if (kind_ != MappingKind::CubeStrip) {
        cx = (*cells)[face][0];
        cy = (*cells)[face][1];
      }
      if (kind_ == MappingKind::CubeVCross && face == 5) {
        s = -s;
        t = -t;
      }
      double fx = std::clamp((s + 1) * 0.5 * face_, 0.0, std::nextafter(static_cast<double>(face_), 0.0));
      double fy = std::clamp((t + 1) * 0.5 * face_, 0.0, std::nextafter(static_cast<double>(face_), 0.0));
      *px = cx * face_ + fx;
      *py = cy * face_ + fy;
      return true;
    }
  }
}

bool Mapping::valid(int x, int y) const {
  Vec3 d;
  return to_direction(x + 0.5, y + 0.5, &d);
}

double Mapping::disc_area(int x, int y) const {
  double a0 = 2.0 * x / width_ - 1, a1 = 2.0 * (x + 1) / width_ - 1;
  double b0 = 1 - 2.0 * (y + 1) / height_, b1 = 1 - 2.0 * y / height_;
  return rect_disc_area(a0, a1, b0, b1);
}

// Angular map: with r = |(a,b)| and θ = πr, dω = sinθ dθ dφ and dA = r dr dφ, so
//      ┌──────────────────────────┐
//      │ dω/dA = π sin(πr) / r    │   (in units where the disc has radius 1)
//      └──────────────────────────┘
// which is analytic in (a,b): Gauss–Legendre is exact to rounding inside the disc. On the rim the
// integrand falls to zero continuously, so pixels cut by the rim use a fine midpoint rule.
double Mapping::angular_solid_angle(int x, int y) const {
  double a0 = 2.0 * x / width_ - 1, a1 = 2.0 * (x + 1) / width_ - 1;
  double b0 = 1 - 2.0 * (y + 1) / height_, b1 = 1 - 2.0 * y / height_;
  auto f = [](double a, double b) {
    double r = std::sqrt(a * a + b * b);
    if (r > 1) return 0.0;
    return r < 1e-12 ? kPi * kPi : kPi * std::sin(kPi * r) / r;
  };
  double rmin2 = 0, rmax2 = 0;
  for (double a : {a0, a1})
    for (double b : {b0, b1}) rmax2 = std::max(rmax2, a * a + b * b);
  double ca = std::clamp(0.0, a0, a1), cb = std::clamp(0.0, b0, b1);
  rmin2 = ca * ca + cb * cb;
  if (rmin2 >= 1) return 0;
  double ha = 0.5 * (a1 - a0), hb = 0.5 * (b1 - b0), ma = 0.5 * (a0 + a1), mb = 0.5 * (b0 + b1);
  if (rmax2 <= 1) {
    // 6-point Gauss–Legendre nodes and weights on [−1, 1].
    static constexpr double xg[6] = {-0.9324695142031521, -0.6612093864662645, -0.2386191860831969,
                                     0.2386191860831969,  0.6612093864662645,  0.9324695142031521};
    static constexpr double wg[6] = {0.1713244923791704, 0.3607615730481386, 0.4679139345726910,
                                     0.4679139345726910, 0.3607615730481386, 0.1713244923791704};
    double s = 0;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) s += wg[i] * wg[j] * f(ma + ha * xg[i], mb + hb * xg[j]);
    return s * ha * hb;
  }
  constexpr int kN = 48;  // rim pixels: error ~ (1/kN)² of a pixel that is itself nearly empty
  double s = 0;
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) s += f(a0 + (i + 0.5) * (a1 - a0) / kN, b0 + (j + 0.5) * (b1 - b0) / kN);
  return s * (a1 - a0) * (b1 - b0) / (kN * kN);
}

// Octahedral map: within each quadrant and each side of |a|+|b| = 1 the map from the square to the
// octahedron is linear, so a pixel maps to at most a few planar polygons; their solid angles are
// exact sums of triangle solid angles.
double Mapping::octahedral_solid_angle(int x, int y) const {
  double a0 = 2.0 * x / width_ - 1, a1 = 2.0 * (x + 1) / width_ - 1;
  double b0 = 2.0 * y / height_ - 1, b1 = 2.0 * (y + 1) / height_ - 1;
  Poly rect = {{a0, b0}, {a1, b0}, {a1, b1}, {a0, b1}};
  double total = 0;
  for (double sa : {-1.0, 1.0})
    for (double sb : {-1.0, 1.0}) {
      Poly q = clip(clip(rect, {-sa, 0}, 0), {0, -sb}, 0);
      if (q.size() < 3) continue;
      for (int side = 0; side < 2; ++side) {
        Poly p = side == 0 ? clip(q, {sa, sb}, 1) : clip(q, {-sa, -sb}, -1);
        if (p.size() < 3) continue;
        // Map vertices; nudge the (a,b) inward so the fold test picks this piece's side.
        std::vector<Vec3> v;
        for (auto pt : p) {
          double y3 = 1 - std::abs(pt.x) - std::abs(pt.y);
          if (side == 0)
            v.push_back({pt.x, std::max(0.0, y3), pt.y});
          else
            v.push_back({(1 - sb * pt.y) * sa, std::min(0.0, y3), (1 - sa * pt.x) * sb});
        }
        for (size_t i = 1; i + 1 < v.size(); ++i) total += triangle_solid_angle(v[0], v[i], v[i + 1]);
      }
    }
  return total;
}

double Mapping::solid_angle_estimate(int x, int y) const {
  switch (kind_) {
    case MappingKind::LatLong:
      return solid_angle(x, y);  // already cheap: two cosines
    case MappingKind::MirrorBall:
    case MappingKind::Angular: {
      double a = 2.0 * (x + 0.5) / width_ - 1, b = 1 - 2.0 * (y + 0.5) / height_;
      double r = std::sqrt(a * a + b * b), area = 4.0 / (static_cast<double>(width_) * height_);
      if (r > 1) return 0.0;
      if (kind_ == MappingKind::MirrorBall) return 4.0 * area;
      return area * (r < 1e-12 ? kPi * kPi : kPi * std::sin(kPi * r) / r);
    }
    case MappingKind::Octahedral:
      return solid_angle(x, y);
    default: {
      int cx = x / face_, cy = y / face_, face;
      bool rot;
      if (!cell_face(cx, cy, &face, &rot)) return 0.0;
      double s = 2.0 * (x - cx * face_ + 0.5) / face_ - 1, t = 2.0 * (y - cy * face_ + 0.5) / face_ - 1;
      double q = s * s + t * t + 1;
      return (4.0 / (static_cast<double>(face_) * face_)) / (q * std::sqrt(q));  // dω = dA / (1+s²+t²)^{3/2}
    }
  }
}

double Mapping::solid_angle(int x, int y) const {
  switch (kind_) {
    case MappingKind::LatLong: {
      double t0 = kPi * y / height_, t1 = kPi * (y + 1) / height_;
      return (kTwoPi / width_) * (std::cos(t0) - std::cos(t1));
    }
    case MappingKind::MirrorBall:
      return 4.0 * disc_area(x, y);
    case MappingKind::Angular:
      return angular_solid_angle(x, y);
    case MappingKind::Octahedral:
      return octahedral_solid_angle(x, y);
    default: {
      int cx = x / face_, cy = y / face_, face;
      bool rot;
      if (!cell_face(cx, cy, &face, &rot)) return 0.0;
      int fx = x - cx * face_, fy = y - cy * face_;
      double s0 = 2.0 * fx / face_ - 1, s1 = 2.0 * (fx + 1) / face_ - 1;
      double t0 = 2.0 * fy / face_ - 1, t1 = 2.0 * (fy + 1) / face_ - 1;
      return cube_rect_solid_angle(s0, s1, t0, t1);
    }
  }
}

}  // namespace ibl::sphere
