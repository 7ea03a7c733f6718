#include "iblkit/geometry/mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"

namespace ibl::geometry {

Vec3 TriMesh::normal(size_t i) const {
  const auto& t = triangles[i];
  return normalize(cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]));
}

double TriMesh::area(size_t i) const {
  const auto& t = triangles[i];
  return 0.5 * length(cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]));
}

double TriMesh::total_area() const {
  double a = 0;
  for (size_t i = 0; i < triangles.size(); ++i) a += area(i);
  return a;
}

void TriMesh::bounds(Vec3* lo, Vec3* hi) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  *lo = {inf, inf, inf};
  *hi = {-inf, -inf, -inf};
  for (const Vec3& p : positions)
    for (int k = 0; k < 3; ++k) {
      (*lo)[k] = std::min((*lo)[k], p[k]);
      (*hi)[k] = std::max((*hi)[k], p[k]);
    }
}

void TriMesh::append(const TriMesh& o) {
  bool keep_uv = (positions.empty() || !uvs.empty()) && !o.uvs.empty();
  bool keep_normals = (positions.empty() || !normals.empty()) && !o.normals.empty();
  auto base = static_cast<uint32_t>(positions.size());
  if (!keep_uv) uvs.clear();
  if (!keep_normals) normals.clear();
  positions.insert(positions.end(), o.positions.begin(), o.positions.end());
  if (keep_uv) uvs.insert(uvs.end(), o.uvs.begin(), o.uvs.end());
  if (keep_normals) normals.insert(normals.end(), o.normals.begin(), o.normals.end());
  for (auto t : o.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

void TriMesh::transform(const Mat3& rotation, double scale, Vec3 translation) {
  for (Vec3& p : positions) p = rotation * (p * scale) + translation;
  for (Vec3& n : normals) n = normalize(rotation * n);
}

void TriMesh::transform(double scale, Vec3 translation) {
  for (Vec3& p : positions) p = p * scale + translation;
}

void TriMesh::flip() {
  for (auto& t : triangles) std::swap(t[1], t[2]);
  for (Vec3& n : normals) n = -n;
}

void TriMesh::compute_normals() {
  std::vector<Vec3> acc(positions.size());
  for (const auto& t : triangles) {
    Vec3 n = cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]);  // length = 2 × area
    for (uint32_t v : t) acc[v] += n;
  }
  normals.resize(positions.size());
  for (size_t i = 0; i < acc.size(); ++i) normals[i] = normalize(acc[i]);
}

void TriMesh::validate(const std::string& what) const {
  if (!uvs.empty() && uvs.size() != positions.size())
    fail(ErrorKind::Format, "{}: {} UVs for {} vertices", what, uvs.size(), positions.size());
  if (!normals.empty() && normals.size() != positions.size())
    fail(ErrorKind::Format, "{}: {} normals for {} vertices", what, normals.size(), positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(positions[i][k])) fail(ErrorKind::Value, "{}: vertex {} is not finite", what, i);
  for (size_t i = 0; i < triangles.size(); ++i)
    for (uint32_t v : triangles[i])
      if (v >= positions.size())
        fail(ErrorKind::Format, "{}: triangle {} names vertex {} of {}", what, i, v, positions.size());
}

TriMesh with_normals(const TriMesh& m, double crease_deg) {
  // Smooth normals within smooth regions, hard edges at creases: each triangle corner averages the
  // (area-weighted) normals of the triangles around its vertex that lie within crease_deg of its
  // own face, and corners of one vertex that end up with different normals become separate vertices.
  const size_t T = m.triangles.size();
  std::vector<Vec3> face(T);  // area-weighted (length = 2 × area)
  std::vector<std::vector<uint32_t>> around(m.positions.size());
  for (size_t t = 0; t < T; ++t) {
    const auto& tri = m.triangles[t];
    face[t] = cross(m.positions[tri[1]] - m.positions[tri[0]], m.positions[tri[2]] - m.positions[tri[0]]);
    for (uint32_t v : tri) around[v].push_back(static_cast<uint32_t>(t));
  }
  const double cos_crease = std::cos(crease_deg * kPi / 180);
  const bool has_uv = m.uvs.size() == m.positions.size();
  TriMesh out;
  out.triangles.reserve(T);
  // Corners of vertex v with identical normals share one output vertex.
  std::vector<std::vector<std::pair<Vec3, uint32_t>>> made(m.positions.size());
  for (size_t t = 0; t < T; ++t) {
    const Vec3 nt = normalize(face[t]);
    std::array<uint32_t, 3> corners{};
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = m.triangles[t][c];
      Vec3 acc;
      for (uint32_t u : around[v])
        if (dot(normalize(face[u]), nt) >= cos_crease) acc += face[u];
      Vec3 n = length(acc) > 0 ? normalize(acc) : nt;
      uint32_t id = UINT32_MAX;
      for (const auto& [nn, k] : made[v])
        if (length(nn - n) < 1e-9) id = k;
      if (id == UINT32_MAX) {
        id = static_cast<uint32_t>(out.vertex_count());
        out.positions.push_back(m.positions[v]);
        out.normals.push_back(n);
        if (has_uv) out.uvs.push_back(m.uvs[v]);
        made[v].push_back({n, id});
      }
      corners[c] = id;
    }
    out.triangles.push_back(corners);
  }
  return out;
}

namespace {

// Appends the rectangle p0, p0+eu, p0+eu+ev, p0+ev with UVs uv0..uv1, front towards `facing`.
void add_rect(TriMesh& m, Vec3 p0, Vec3 eu, Vec3 ev, Vec2 uv0, Vec2 uv1, Vec3 facing) {
  auto b = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), {p0, p0 + eu, p0 + eu + ev, p0 + ev});
  m.uvs.insert(m.uvs.end(), {uv0, {uv1.x, uv0.y}, uv1, {uv0.x, uv1.y}});
  if (dot(cross(eu, ev), facing) >= 0) {
    m.triangles.push_back({b, b + 1, b + 2});
    m.triangles.push_back({b, b + 2, b + 3});
  } else {
    m.triangles.push_back({b, b + 2, b + 1});
    m.triangles.push_back({b, b + 3, b + 2});
  }
}

Vec3 axis_vec(int k) { return {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0}; }

// A generated mesh of about `triangles` triangles: at most kMaxGeneratedTriangles, and within memory
// (about 64 bytes a triangle with its vertices, normals, UVs and the ray tracer's copy).
constexpr double kMaxGeneratedTriangles = 1e8;
void check_triangles(double triangles, const std::string& what, const char* hint) {
  if (triangles > kMaxGeneratedTriangles)
    fail(ErrorKind::Value, "{}: {:.3g} triangles exceed the {:g} supported (about {:.3g} GB); {}", what, triangles,
         kMaxGeneratedTriangles, triangles * 64 / 1e9, hint);
  require_allocation(what, triangles, 64, hint);
}

void check_positive(double v, const char* what) {
  if (!(v > 0) || !std::isfinite(v)) fail(ErrorKind::Value, "{} must be positive and finite, got {}", what, v);
}

}  // namespace

TriMesh make_quad(Vec3 center, Vec3 normal, Vec3 up, double w, double h) {
  check_positive(w, "quad width");
  check_positive(h, "quad height");
  Vec3 n = normalize(normal);
  if (length(n) == 0) fail(ErrorKind::Value, "quad normal is zero");
  Vec3 v = up - n * dot(up, n);
  if (length(v) < 1e-9) v = Frame::from_normal(n).b;
  v = normalize(v);
  Vec3 u = cross(v, n);  // u × v = n
  TriMesh m;
  add_rect(m, center - u * (w / 2) - v * (h / 2), u * w, v * h, {0, 0}, {1, 1}, n);
  return m;
}

TriMesh make_disc(Vec3 center, Vec3 normal, double radius, int segments) {
  check_positive(radius, "disc radius");
  check_triangles(segments, fmt::format("a disc of {} segments", segments), "choose fewer segments");
  Vec3 n = normalize(normal);
  if (length(n) == 0) fail(ErrorKind::Value, "disc normal is zero");
  Frame f = Frame::from_normal(n);
  TriMesh m;
  m.positions.push_back(center);
  m.uvs.push_back({0.5, 0.5});
  for (int i = 0; i < segments; ++i) {
    double a = kTwoPi * i / segments, c = std::cos(a), s = std::sin(a);
    m.positions.push_back(center + (f.t * c + f.b * s) * radius);
    m.uvs.push_back({0.5 + 0.5 * c, 0.5 + 0.5 * s});
  }
  for (int i = 0; i < segments; ++i)  // t × b = n, so increasing angle is counter-clockwise
    m.triangles.push_back({0, static_cast<uint32_t>(1 + i), static_cast<uint32_t>(1 + (i + 1) % segments)});
  return m;
}

TriMesh make_sphere(Vec3 center, double radius, int rings, int segments, bool inward) {
  check_positive(radius, "sphere radius");
  if (rings < 2 || segments < 3)
    fail(ErrorKind::Value, "sphere needs ≥ 2 rings and ≥ 3 segments ({} and {} given)", rings, segments);
  check_triangles(2.0 * rings * segments, fmt::format("a sphere of {} rings and {} segments", rings, segments),
                  "choose fewer rings or segments");
  TriMesh m;
  for (int r = 0; r <= rings; ++r) {
    double th = kPi * r / rings;
    for (int s = 0; s <= segments; ++s) {
      double ph = kTwoPi * s / segments;
      Vec3 d{std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)};
      m.positions.push_back(center + d * radius);
      m.normals.push_back(inward ? -d : d);
      m.uvs.push_back({static_cast<double>(s) / segments, 1.0 - static_cast<double>(r) / rings});
    }
  }
  auto id = [&](int r, int s) { return static_cast<uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = id(r, s), b = id(r + 1, s), c = id(r + 1, s + 1), d = id(r, s + 1);
      if (r != 0) m.triangles.push_back({a, b, d});
      if (r != rings - 1) m.triangles.push_back({b, c, d});
    }
  // Orient each triangle: outwards is away from the centre.
  for (auto& t : m.triangles) {
    Vec3 p0 = m.positions[t[0]];
    Vec3 nn = cross(m.positions[t[1]] - p0, m.positions[t[2]] - p0);
    bool out = dot(nn, p0 - center) > 0;
    if (out == inward) std::swap(t[1], t[2]);
  }
  return m;
}

TriMesh make_blob(int triangles, double size) {
  check_triangles(triangles, fmt::format("a blob of {} triangles", triangles), "choose fewer triangles");
  // rings × segments × 2 ≈ triangles with segments = 2 rings.
  int rings = std::max(4, static_cast<int>(std::sqrt(triangles / 4.0)));
  int segments = 2 * rings;
  auto r = [&](Vec3 d) {
    double body = 1.0 + 0.18 * d.y * d.y * (d.y < 0 ? 0.5 : -0.4) + 0.12 * d.x * d.z;  // pear-like body
    double bumps = 0.04 * std::sin(5 * d.x + 1.3) * std::sin(4 * d.z + 0.7) * std::cos(3 * d.y);
    // Two ears: narrow lobes up and slightly back.
    auto lobe = [](Vec3 d, Vec3 axis, double sharp) { return std::pow(std::max(0.0, dot(d, normalize(axis))), sharp); };
    double ears = 0.55 * lobe(d, {0.25, 1.0, 0.35}, 60) + 0.55 * lobe(d, {-0.25, 1.0, 0.35}, 60);
    double snout = 0.25 * lobe(d, {0, 0.2, -1}, 12);
    return 0.5 * size * (body + bumps + ears + snout);
  };
  TriMesh m = make_sphere({0, 0, 0}, 1.0, rings, segments);
  for (Vec3& p : m.positions) p = p * r(p);  // p is the unit direction d on the sphere
  m.compute_normals();
  return m;
}

TriMesh make_floor(double size, double height) {
  TriMesh m = make_quad({0, height, 0}, {0, 1, 0}, {0, 0, -1}, size, size);
  m.normals.assign(m.positions.size(), Vec3{0, 1, 0});
  return m;
}

TriMesh make_cylinder(Vec3 base, Vec3 axis, double radius, int segments, bool caps) {
  check_positive(radius, "cylinder radius");
  check_triangles(4.0 * segments, fmt::format("a cylinder of {} segments", segments), "choose fewer segments");
  check_positive(length(axis), "cylinder height");
  Vec3 a = normalize(axis);
  Frame f = Frame::from_normal(a);
  TriMesh m;
  for (int i = 0; i <= segments; ++i) {
    double ang = kTwoPi * i / segments;
    Vec3 r = (f.t * std::cos(ang) + f.b * std::sin(ang)) * radius;
    m.positions.push_back(base + r);
    m.positions.push_back(base + axis + r);
    double u = static_cast<double>(i) / segments;
    m.uvs.push_back({u, 0});
    m.uvs.push_back({u, 1});
  }
  for (int i = 0; i < segments; ++i) {
    auto b0 = static_cast<uint32_t>(2 * i), t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
    m.triangles.push_back({b0, b1, t1});  // t × b = a: counter-clockwise seen from outside
    m.triangles.push_back({b0, t1, t0});
  }
  if (caps) {
    m.append(make_disc(base, -a, radius, segments));
    m.append(make_disc(base + axis, a, radius, segments));
  }
  return m;
}

TriMesh make_box(Vec3 lo, Vec3 hi, bool inward) {
  RoomDesc d;
  d.lo = lo;
  d.hi = hi;
  TriMesh m = make_room(d);
  if (!inward) m.flip();
  return m;
}

TriMesh make_room(const RoomDesc& desc) {
  for (int k = 0; k < 3; ++k)
    if (!(desc.hi[k] > desc.lo[k])) fail(ErrorKind::Value, "room: max[{}] must exceed min[{}]", k, k);
  TriMesh m;
  for (int k = 0; k < 3; ++k)
    for (int side = 0; side < 2; ++side) {
      if (desc.omit[2 * k + side]) continue;
      int a = k == 0 ? 1 : 0, b = k == 2 ? 1 : 2;  // the other two axes, a < b
      std::vector<double> ca{desc.lo[a], desc.hi[a]}, cb{desc.lo[b], desc.hi[b]};
      std::vector<const Opening*> holes;
      for (const Opening& o : desc.openings)
        if (o.axis == k && o.at_max == (side == 1)) {
          holes.push_back(&o);
          ca.insert(ca.end(), {std::clamp(o.lo.x, desc.lo[a], desc.hi[a]), std::clamp(o.hi.x, desc.lo[a], desc.hi[a])});
          cb.insert(cb.end(), {std::clamp(o.lo.y, desc.lo[b], desc.hi[b]), std::clamp(o.hi.y, desc.lo[b], desc.hi[b])});
        }
      for (auto* c : {&ca, &cb}) {
        std::sort(c->begin(), c->end());
        c->erase(std::unique(c->begin(), c->end()), c->end());
      }
      double plane = side ? desc.hi[k] : desc.lo[k];
      Vec3 inward = axis_vec(k) * (side ? -1.0 : 1.0);
      double la = desc.hi[a] - desc.lo[a], lb = desc.hi[b] - desc.lo[b];
      for (size_t i = 0; i + 1 < ca.size(); ++i)
        for (size_t j = 0; j + 1 < cb.size(); ++j) {
          double ma = 0.5 * (ca[i] + ca[i + 1]), mb = 0.5 * (cb[j] + cb[j + 1]);
          bool in_hole = std::any_of(holes.begin(), holes.end(), [&](const Opening* o) {
            return ma > o->lo.x && ma < o->hi.x && mb > o->lo.y && mb < o->hi.y;
          });
          if (in_hole) continue;
          Vec3 p0;
          p0[k] = plane;
          p0[a] = ca[i];
          p0[b] = cb[j];
          Vec2 uv0{(ca[i] - desc.lo[a]) / la, (cb[j] - desc.lo[b]) / lb};
          Vec2 uv1{(ca[i + 1] - desc.lo[a]) / la, (cb[j + 1] - desc.lo[b]) / lb};
          add_rect(m, p0, axis_vec(a) * (ca[i + 1] - ca[i]), axis_vec(b) * (cb[j + 1] - cb[j]), uv0, uv1, inward);
        }
    }
  return m;
}

}  // namespace ibl::geometry
