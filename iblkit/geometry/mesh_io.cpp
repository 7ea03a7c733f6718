#include "iblkit/geometry/mesh_io.h"
#include "iblkit/core/input_file.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"

namespace ibl::geometry {

namespace {
void gather(const aiScene* sc, const aiNode* node, const aiMatrix4x4& parent, TriMesh& out, bool& all_uv) {
  aiMatrix4x4 m = parent * node->mTransformation;
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    const aiMesh* am = sc->mMeshes[node->mMeshes[i]];
    TriMesh part;
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      aiVector3D p = m * am->mVertices[v];
      part.positions.push_back({p.x, p.y, p.z});
      if (am->HasTextureCoords(0)) part.uvs.push_back({am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y});
    }
    all_uv = all_uv && am->HasTextureCoords(0);
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left by triangulation
      part.triangles.push_back({face.mIndices[0], face.mIndices[1], face.mIndices[2]});
    }
    if (!all_uv) part.uvs.clear();
    out.append(part);
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) gather(sc, node->mChildren[c], m, out, all_uv);
}
// assimp's PLY reader (5.2) loops forever on a header without its "end_header" line: a file that
// starts with "ply" must have that line within its first 64 KiB (found by fuzz/mesh_fuzz.cpp).
void check_ply_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  if (head.rfind("ply", 0) != 0) return;
  size_t end = std::string::npos;
  for (size_t at = head.find("end_header"); at != std::string::npos; at = head.find("end_header", at + 1)) {
    const bool starts_line = at > 0 && head[at - 1] == '\n';
    const size_t after = at + 10;
    if (starts_line && (after >= head.size() || head[after] == '\n' || head[after] == '\r' || head[after] == ' ')) {
      end = at;
      break;
    }
  }
  if (end == std::string::npos)
    fail(ErrorKind::Format, "{}: PLY header has no \"end_header\" line (within the first 64 KiB)", path);
  // assimp allocates what an "element NAME COUNT" line declares before reading a byte of it (a header
  // declaring 4294967295 elements asked for 103 GB; found by fuzz/mesh_fuzz.cpp): every element takes at
  // least a byte, so no number on an element line may exceed the file's size.
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) fail(ErrorKind::Io, "{}: cannot stat ({})", path, ec.message());
  for (size_t line = 0; line < end;) {
    size_t eol = head.find('\n', line);
    if (eol == std::string::npos || eol > end) eol = end;
    if (head.compare(line, 7, "element") == 0)
      for (size_t i = line + 7; i < eol;) {
        if (head[i] < '0' || head[i] > '9') {
          ++i;
          continue;
        }
        uintmax_t n = 0;
        bool big = false;
        for (; i < eol && head[i] >= '0' && head[i] <= '9'; ++i) {
          n = n * 10 + uintmax_t(head[i] - '0');
          big = big || n > bytes;
        }
        if (big)
          fail(ErrorKind::Format, "{}: PLY header line \"{}\" declares more elements than the file's {} bytes can hold",
               path, head.substr(line, std::min<size_t>(eol - line, 60)), bytes);
      }
    line = eol + 1;
  }
}
}  // namespace

TriMesh read_mesh(const std::string& path) {
  require_input_file(path, "a mesh");
  check_ply_header(path);
  Assimp::Importer imp;
  const aiScene* sc = imp.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                             aiProcess_SortByPType | aiProcess_PreTransformVertices);
  if (!sc || !sc->mRootNode) fail(ErrorKind::Format, "{}: cannot read mesh ({})", path, imp.GetErrorString());
  TriMesh out;
  bool all_uv = true;
  gather(sc, sc->mRootNode, aiMatrix4x4(), out, all_uv);
  if (!all_uv) out.uvs.clear();
  if (out.triangle_count() == 0) fail(ErrorKind::Format, "{}: the mesh has no triangles", path);
  out.validate(path);
  return out;
}

void write_obj(const std::string& path, const TriMesh& mesh, const std::string& comment) {
  AtomicFile file(path);
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(file.temp_path().c_str(), "w"), &std::fclose);
  if (!f) fail(ErrorKind::Io, "{}: cannot write", path);
  if (!comment.empty()) std::fprintf(f.get(), "# %s\n", comment.c_str());
  for (const Vec3& p : mesh.positions) std::fprintf(f.get(), "v %.6g %.6g %.6g\n", p.x, p.y, p.z);
  bool uv = !mesh.uvs.empty();
  for (const Vec2& t : mesh.uvs) std::fprintf(f.get(), "vt %.6g %.6g\n", t.x, t.y);
  for (const auto& t : mesh.triangles) {
    if (uv)
      std::fprintf(f.get(), "f %u/%u %u/%u %u/%u\n", t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1);
    else
      std::fprintf(f.get(), "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
  }
  bool ok = !std::ferror(f.get());
  ok = std::fclose(f.release()) == 0 && ok;
  if (!ok) fail(ErrorKind::Io, "{}: write failed", path);
  file.commit();
}

}  // namespace ibl::geometry
