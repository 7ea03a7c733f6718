#include "iblkit/render/gl/uploads.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "iblkit/core/error.h"

namespace ibl::render::gl {

namespace {

// A mesh as the GPU takes it: float positions, normals and UVs (zeros where the mesh has none),
// uint32 indices.
struct Packed {
  std::vector<float> positions, normals, uvs;
  std::vector<uint32_t> indices;
};

Packed pack(const geometry::TriMesh& m) {
  Packed p;
  const size_t n = m.vertex_count();
  p.positions.resize(3 * n);
  p.normals.resize(3 * n);
  p.uvs.assign(2 * n, 0.0f);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      p.positions[3 * i + k] = static_cast<float>(m.positions[i][k]);
      p.normals[3 * i + k] = static_cast<float>(m.normals[i][k]);
    }
  if (m.has_uvs())
    for (size_t i = 0; i < n; ++i) {
      p.uvs[2 * i] = static_cast<float>(m.uvs[i].x);
      p.uvs[2 * i + 1] = static_cast<float>(m.uvs[i].y);
    }
  p.indices.resize(3 * m.triangle_count());
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) p.indices[3 * t + k] = m.triangles[t][k];
  return p;
}

MeshBuffers upload(const Packed& m) {
  MeshBuffers b;
  glCreateVertexArrays(1, &b.vao);
  glCreateBuffers(3, b.vbo);
  glCreateBuffers(1, &b.ebo);
  glNamedBufferStorage(b.vbo[0], static_cast<GLsizeiptr>(std::max<size_t>(1, m.positions.size()) * sizeof(float)),
                       m.positions.data(), 0);
  glNamedBufferStorage(b.vbo[1], static_cast<GLsizeiptr>(std::max<size_t>(1, m.normals.size()) * sizeof(float)),
                       m.normals.data(), 0);
  glNamedBufferStorage(b.vbo[2], static_cast<GLsizeiptr>(std::max<size_t>(1, m.uvs.size()) * sizeof(float)),
                       m.uvs.data(), 0);
  glNamedBufferStorage(b.ebo, static_cast<GLsizeiptr>(std::max<size_t>(1, m.indices.size()) * sizeof(uint32_t)),
                       m.indices.data(), 0);
  for (int a = 0; a < 3; ++a) {
    const int n = a == 2 ? 2 : 3;
    glVertexArrayVertexBuffer(b.vao, a, b.vbo[a], 0, n * sizeof(float));
    glVertexArrayAttribFormat(b.vao, a, n, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(b.vao, a, a);
    glEnableVertexArrayAttrib(b.vao, a);
  }
  glVertexArrayElementBuffer(b.vao, b.ebo);
  b.count = static_cast<int>(m.indices.size());
  return b;
}

// The same values, bit for bit (a moved or changed mesh is uploaded again).
template <typename T>
bool same_values(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void release_buffers(MeshBuffers& b) {
  glDeleteVertexArrays(1, &b.vao);
  glDeleteBuffers(3, b.vbo);
  glDeleteBuffers(1, &b.ebo);
}

}  // namespace

Uploads::~Uploads() {
  if (color_tex_) glDeleteTextures(1, &color_tex_);
  if (spots_.tex) glDeleteTextures(1, &spots_.tex);
  if (grid_tex_) glDeleteTextures(1, &grid_tex_);
  geometry_.release();
}

unsigned Uploads::color_texture(int w, int h) {
  if (color_tex_ && color_w_ == w && color_h_ == h) return color_tex_;
  if (color_tex_) glDeleteTextures(1, &color_tex_);
  glCreateTextures(GL_TEXTURE_2D, 1, &color_tex_);
  glTextureStorage2D(color_tex_, 1, GL_RGBA32F, w, h);
  color_w_ = w;
  color_h_ = h;
  return color_tex_;
}

void Uploads::Geometry::release() {
  for (auto& m : meshes) release_buffers(m);
  if (ssbo[0]) glDeleteBuffers(5, ssbo);
  *this = {};
}

const Uploads::Geometry& Uploads::geometry(const std::vector<RenderObject>& objects, bool deferred) {
  bool same = geometry_.keys.size() == objects.size();
  for (size_t i = 0; same && i < objects.size(); ++i) {
    const geometry::TriMesh& a = *objects[i].mesh;
    const geometry::TriMesh& b = geometry_.keys[i];
    same = same_values(a.positions, b.positions) && same_values(a.normals, b.normals) && same_values(a.uvs, b.uvs) &&
           same_values(a.triangles, b.triangles);
  }
  if (same && (!deferred || geometry_.ssbo[0])) return geometry_;
  std::vector<Packed> packed;
  for (const auto& o : objects) packed.push_back(pack(*o.mesh));
  if (!same) {
    geometry_.release();
    for (size_t i = 0; i < objects.size(); ++i) {
      geometry_.meshes.push_back(upload(packed[i]));
      geometry_.keys.push_back(*objects[i].mesh);
    }
  }
  if (deferred && !geometry_.ssbo[0]) {
    // Geometry for the compute pass: all objects' vertices and indices, and where each starts.
    if (objects.size() > 255)
      fail(ErrorKind::Value, "the deferred path draws at most 255 objects ({} given)", objects.size());
    std::vector<uint32_t> object_table;
    std::vector<float> pos, nrm, uvs;
    std::vector<uint32_t> idx;
    for (const Packed& p : packed) {
      if (p.indices.size() / 3 >= (1u << 24))
        fail(ErrorKind::Value, "a mesh of {} triangles is over the deferred path's 2^24", p.indices.size() / 3);
      object_table.insert(object_table.end(),
                          {static_cast<uint32_t>(pos.size() / 3), static_cast<uint32_t>(idx.size()), 0u, 0u});
      pos.insert(pos.end(), p.positions.begin(), p.positions.end());
      nrm.insert(nrm.end(), p.normals.begin(), p.normals.end());
      uvs.insert(uvs.end(), p.uvs.begin(), p.uvs.end());
      idx.insert(idx.end(), p.indices.begin(), p.indices.end());
    }
    glCreateBuffers(5, geometry_.ssbo);
    glNamedBufferStorage(geometry_.ssbo[0], static_cast<GLsizeiptr>(std::max<size_t>(4, object_table.size()) * 4),
                         object_table.data(), 0);
    glNamedBufferStorage(geometry_.ssbo[1], static_cast<GLsizeiptr>(std::max<size_t>(1, pos.size()) * 4), pos.data(),
                         0);
    glNamedBufferStorage(geometry_.ssbo[2], static_cast<GLsizeiptr>(std::max<size_t>(1, nrm.size()) * 4), nrm.data(),
                         0);
    glNamedBufferStorage(geometry_.ssbo[3], static_cast<GLsizeiptr>(std::max<size_t>(1, idx.size()) * 4), idx.data(),
                         0);
    glNamedBufferStorage(geometry_.ssbo[4], static_cast<GLsizeiptr>(std::max<size_t>(1, uvs.size()) * 4), uvs.data(),
                         0);
  }
  return geometry_;
}

// (Compared in full: a memcmp costs a tenth of packing and uploading the values again.)
unsigned Uploads::grid_texture(const ilf::SHGrid& g) {
  const ilf::GridDesc &gd = g.grid(), &key = grid_key_.grid();
  if (grid_tex_ && gd.nx == key.nx && gd.ny == key.ny && gd.nz == key.nz && g.bands() == grid_key_.bands() &&
      g.data() == grid_key_.data())
    return grid_tex_;
  if (grid_tex_) glDeleteTextures(1, &grid_tex_);
  grid_tex_ = 0;  // (nothing stale is left if what follows throws)
  grid_key_ = {};
  const int K = g.coeff_count();
  const size_t points = static_cast<size_t>(gd.count());
  std::vector<float> packed(points * K * 4, 0.0f);
  for (int k = 0; k < K; ++k)
    for (size_t p = 0; p < points; ++p)
      for (int c = 0; c < 3; ++c) packed[(static_cast<size_t>(k) * points + p) * 4 + c] = g.data()[(p * K + k) * 3 + c];
  glCreateTextures(GL_TEXTURE_3D, 1, &grid_tex_);
  glTextureStorage3D(grid_tex_, 1, GL_RGBA16F, gd.nx, gd.ny, gd.nz * K);
  glTextureSubImage3D(grid_tex_, 0, 0, 0, 0, gd.nx, gd.ny, gd.nz * K, GL_RGBA, GL_FLOAT, packed.data());
  glTextureParameteri(grid_tex_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(grid_tex_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
    glTextureParameteri(grid_tex_, w, GL_CLAMP_TO_EDGE);
  grid_key_ = g;
  return grid_tex_;
}

const Uploads::SpotTextures& Uploads::spot_textures(const std::vector<nearfield::TexturedSpotlight>& lights) {
  bool same = spots_.keys.size() == lights.size();
  for (size_t i = 0; same && i < lights.size(); ++i) same = spots_.keys[i] == lights[i].mips;
  if (same && spots_.tex) return spots_;
  if (spots_.tex) glDeleteTextures(1, &spots_.tex);
  spots_ = {};
  const auto& first = lights[0];
  if (!first.mips || first.mips->empty()) fail(ErrorKind::Value, "textured spotlight 0 has no texture");
  const int tw = (*first.mips)[0].width(), th = (*first.mips)[0].height();
  const int levels = static_cast<int>(first.mips->size());
  for (size_t i = 0; i < lights.size(); ++i) {
    const auto& sp = lights[i];
    if (!sp.mips || sp.mips->size() != static_cast<size_t>(levels) || (*sp.mips)[0].width() != tw ||
        (*sp.mips)[0].height() != th)
      fail(ErrorKind::Unsupported,
           "the GL renderer takes textured spotlights of one texture size per frame (spotlight {} differs from "
           "spotlight 0)",
           i);
    for (int lv = 0; lv < levels; ++lv)
      if ((*sp.mips)[lv].channels() != 3) fail(ErrorKind::Value, "spotlight {} mip {} is not RGB", i, lv);
  }
  GLuint tex = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &tex);
  // Half floats: half the memory of RGBA32F (the paper stored sRGBE, 4 bytes a texel, for the same
  // reason); 11-bit mantissas, well inside the agreement test's tolerance.
  glTextureStorage3D(tex, levels, GL_RGBA16F, tw, th, static_cast<GLsizei>(lights.size()));
  std::vector<float> rgba;
  for (size_t i = 0; i < lights.size(); ++i) {
    const auto& sp = lights[i];
    // Half floats hold up to 65504 with 11-bit mantissas: each texture is stored divided by its
    // largest |texel| (measured radiance of a small LED reaches 10⁶ and more), the shader
    // multiplies it back.
    float peak = 0;
    for (size_t k = 0; k < (*sp.mips)[0].size(); ++k) peak = std::max(peak, std::abs((*sp.mips)[0].data()[k]));
    const float scale = peak > 0 && std::isfinite(peak) ? peak : 1.0f;
    spots_.scale.push_back(scale);
    for (int lv = 0; lv < levels; ++lv) {
      const Image& im = (*sp.mips)[lv];
      rgba.assign(im.pixel_count() * 4, 0.0f);
      for (size_t k = 0; k < im.pixel_count(); ++k)
        for (int c = 0; c < 3; ++c) rgba[k * 4 + c] = im.data()[k * 3 + c] / scale;
      glTextureSubImage3D(tex, lv, 0, 0, static_cast<GLint>(i), im.width(), im.height(), 1, GL_RGBA, GL_FLOAT,
                          rgba.data());
    }
    spots_.keys.push_back(sp.mips);
  }
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_BASE_LEVEL, 0);
  glTextureParameteri(tex, GL_TEXTURE_MAX_LEVEL, levels - 1);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float zero_border[4] = {0, 0, 0, 0};
  glTextureParameterfv(tex, GL_TEXTURE_BORDER_COLOR, zero_border);
  spots_.tex = tex;
  spots_.levels = levels;
  return spots_;
}

}  // namespace ibl::render::gl
