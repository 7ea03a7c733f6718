#include "iblkit/render/mesh.h"

#include <algorithm>
#include <cmath>

#include "iblkit/core/error.h"

namespace ibl::render {

void Mesh::bounds(Vec3* lo, Vec3* hi) const {
  *lo = {1e300, 1e300, 1e300};
  *hi = {-1e300, -1e300, -1e300};
  for (size_t i = 0; i < vertex_count(); ++i) {
    Vec3 p = position(i);
    for (int k = 0; k < 3; ++k) {
      (*lo)[k] = std::min((*lo)[k], p[k]);
      (*hi)[k] = std::max((*hi)[k], p[k]);
    }
  }
}

void Mesh::append(const Mesh& o) {
  uint32_t base = static_cast<uint32_t>(vertex_count());
  const bool keep_uvs = (has_uvs() || vertex_count() == 0) && o.has_uvs();
  if (keep_uvs) uvs.insert(uvs.end(), o.uvs.begin(), o.uvs.end());
  else uvs.clear();
  positions.insert(positions.end(), o.positions.begin(), o.positions.end());
  normals.insert(normals.end(), o.normals.begin(), o.normals.end());
  for (uint32_t i : o.indices) indices.push_back(base + i);
}

void Mesh::transform(double s, Vec3 t) {
  for (size_t i = 0; i < vertex_count(); ++i)
    for (int k = 0; k < 3; ++k) positions[3 * i + k] = static_cast<float>(positions[3 * i + k] * s + t[k]);
}

void Mesh::compute_normals() {
  std::vector<Vec3> acc(vertex_count());
  for (size_t t = 0; t < triangle_count(); ++t) {
    uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
    Vec3 n = cross(position(b) - position(a), position(c) - position(a));  // length = 2 × area
    acc[a] += n;
    acc[b] += n;
    acc[c] += n;
  }
  normals.resize(positions.size());
  for (size_t i = 0; i < acc.size(); ++i) {
    Vec3 n = normalize(acc[i]);
    normals[3 * i] = static_cast<float>(n.x);
    normals[3 * i + 1] = static_cast<float>(n.y);
    normals[3 * i + 2] = static_cast<float>(n.z);
  }
}

namespace {
// A (rings+1) × (segments+1) grid over the sphere, radius given per direction by r(d).
template <typename R>
Mesh sphere_grid(int rings, int segments, R&& r) {
  if (rings < 2 || segments < 3) fail(ErrorKind::Value, "sphere needs ≥ 2 rings and ≥ 3 segments");
  Mesh m;
  for (int i = 0; i <= rings; ++i) {
    double th = kPi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      double ph = kTwoPi * j / segments;
      Vec3 d{std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)};
      Vec3 p = d * r(d);
      m.positions.insert(m.positions.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
      m.uvs.insert(m.uvs.end(), {static_cast<float>(static_cast<double>(j) / segments), static_cast<float>(1.0 - static_cast<double>(i) / rings)});
    }
  }
  auto id = [&](int i, int j) { return static_cast<uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      if (i > 0) m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i, j + 1)});
      if (i + 1 < rings) m.indices.insert(m.indices.end(), {id(i, j + 1), id(i + 1, j), id(i + 1, j + 1)});
    }
  return m;
}
}  // namespace

Mesh from_trimesh(const geometry::TriMesh& m, double crease_deg) {
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
  Mesh out;
  out.indices.reserve(T * 3);
  // Corners of vertex v with identical normals share one output vertex.
  std::vector<std::vector<std::pair<Vec3, uint32_t>>> made(m.positions.size());
  for (size_t t = 0; t < T; ++t) {
    const Vec3 nt = normalize(face[t]);
    for (uint32_t v : m.triangles[t]) {
      Vec3 acc;
      for (uint32_t u : around[v])
        if (dot(normalize(face[u]), nt) >= cos_crease) acc += face[u];
      Vec3 n = length(acc) > 0 ? normalize(acc) : nt;
      uint32_t id = UINT32_MAX;
      for (const auto& [nn, k] : made[v])
        if (length(nn - n) < 1e-9) id = k;
      if (id == UINT32_MAX) {
        id = static_cast<uint32_t>(out.vertex_count());
        Vec3 p = m.positions[v];
        out.positions.insert(out.positions.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
        out.normals.insert(out.normals.end(), {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)});
        if (has_uv) out.uvs.insert(out.uvs.end(), {static_cast<float>(m.uvs[v].x), static_cast<float>(m.uvs[v].y)});
        made[v].push_back({n, id});
      }
      out.indices.push_back(id);
    }
  }
  return out;
}

Mesh make_sphere(double radius, int rings, int segments) {
  Mesh m = sphere_grid(rings, segments, [&](Vec3) { return radius; });
  m.normals.resize(m.positions.size());
  for (size_t i = 0; i < m.vertex_count(); ++i) {
    Vec3 n = normalize(m.position(i));
    m.normals[3 * i] = static_cast<float>(n.x);
    m.normals[3 * i + 1] = static_cast<float>(n.y);
    m.normals[3 * i + 2] = static_cast<float>(n.z);
  }
  return m;
}

Mesh make_blob(int triangles, double size) {
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
  Mesh m = sphere_grid(rings, segments, r);
  m.compute_normals();
  return m;
}

Mesh make_floor(double size, double height) {
  Mesh m;
  float h = static_cast<float>(size / 2), y = static_cast<float>(height);
  m.positions = {-h, y, -h, h, y, -h, h, y, h, -h, y, h};
  m.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  m.uvs = {0, 1, 1, 1, 1, 0, 0, 0};
  m.indices = {0, 2, 1, 0, 3, 2};
  return m;
}

}  // namespace ibl::render
