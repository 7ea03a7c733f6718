#include "iblkit/engine/gltf_ibl.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include <fmt/format.h>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/engine/export.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/rgbd.h"
#include "iblkit/sh/export.h"

namespace ibl::engine {

namespace fs = std::filesystem;

namespace {
constexpr const char* kFaceNames[6] = {"px", "nx", "py", "ny", "pz", "nz"};

Image flip_rows(const Image& img) {
  Image out(img.width(), img.height(), img.channels());
  const size_t row = static_cast<size_t>(img.width()) * img.channels();
  for (int y = 0; y < img.height(); ++y) std::copy_n(img.pixel(0, img.height() - 1 - y), row, out.pixel(0, y));
  return out;
}

// A file name as a URI reference (RFC 3986): everything but the unreserved characters percent-encoded.
std::string uri_of(const std::string& name) {
  std::string u;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~')
      u += static_cast<char>(c);
    else
      u += fmt::format("%{:02X}", c);
  }
  return u;
}

std::string face_path(const std::string& pattern, int level, int face) {
  std::string s = pattern;
  s.replace(s.find("{level}"), 7, std::to_string(level));
  s.replace(s.find("{face}"), 6, kFaceNames[face]);
  return s;
}
}  // namespace

Image gltf_specular_image(const Image& face) { return io::rgbd_encode_image(flip_rows(face)); }
Image gltf_specular_face(const Image& image) { return flip_rows(io::rgbd_decode_image(image)); }

CubeChain read_cube_faces(const std::string& pattern) {
  if (pattern.find("{level}") == std::string::npos || pattern.find("{face}") == std::string::npos)
    fail(ErrorKind::Value, "{}: the pattern of cube faces needs {{level}} and {{face}}", pattern);
  CubeChain chain;
  for (int level = 0; level < 31; ++level) {
    int present = 0;
    for (int f = 0; f < 6; ++f) present += fs::exists(face_path(pattern, level, f)) ? 1 : 0;
    if (present == 0) break;
    if (present < 6) {
      for (int f = 0; f < 6; ++f)
        if (!fs::exists(face_path(pattern, level, f)))
          fail(ErrorKind::Io, "{}: level {} has {} of its six faces ({} is missing)", pattern, level, present,
               face_path(pattern, level, f));
    }
    const int want = level == 0 ? 0 : std::max(1, chain.size(0) >> level);
    if (level > 0 && chain.size(level - 1) == 1)
      fail(ErrorKind::Value, "{}: level {} follows a 1×1 level", pattern, level);
    Image strip;
    for (int f = 0; f < 6; ++f) {
      const std::string p = face_path(pattern, level, f);
      io::ReadDesc rd;
      rd.max_channels = 3;
      Image face = io::read_image(p, rd);
      if (face.channels() < 3) face = face.with_channels(3);
      const int s = face.width();
      if (face.height() != s)
        fail(ErrorKind::Value, "{}: a cube face must be square (got {}×{})", p, face.width(), face.height());
      if (level == 0 && f == 0 && (s & (s - 1)) != 0)
        fail(ErrorKind::Value, "{}: face size {} is not a power of two", p, s);
      if (f == 0 && level > 0 && s != want)
        fail(ErrorKind::Value, "{}: level {} must be {}×{} (level 0 is {}×{}), got {}×{}", p, level, want, want,
             chain.size(0), chain.size(0), s, s);
      if (f == 0) strip = Image(6 * s, s, 3);
      if (s != strip.height())
        fail(ErrorKind::Value, "{}: {}×{}, but the level's +X face is {}×{}", p, s, s, strip.height(), strip.height());
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) strip.set_rgb(f * s + x, y, face.rgb(x, y));
    }
    chain.levels.push_back(std::move(strip));
  }
  if (chain.levels.empty())
    fail(ErrorKind::Io, "{}: no level 0 with all six faces ({} missing)", pattern, face_path(pattern, 0, 0));
  return chain;
}

std::string gltf_specular_image_name(const std::string& gltf_path, int level, int face) {
  fs::path p(gltf_path);
  return (p.parent_path() / fmt::format("{}_m{}_{}.png", p.stem().string(), level, kFaceNames[face])).string();
}

std::vector<std::string> write_gltf_ibl(const std::string& gltf_path, const sh::Coeffs& radiance,
                                        const CubeChain& specular) {
  if (specular.count() < 1) fail(ErrorKind::Value, "{}: the specular cube has no levels", gltf_path);
  sh::GltfSpecular spec;
  spec.size = specular.size(0);
  std::vector<std::string> written;
  io::WriteDesc data;
  data.data = true;
  for (int m = 0; m < specular.count(); ++m) {
    std::array<std::string, 6> uris;
    for (int f = 0; f < 6; ++f) {
      const std::string path = gltf_specular_image_name(gltf_path, m, f);
      io::write_image(path, gltf_specular_image(cube_face(specular, m, f)), data);
      written.push_back(path);
      uris[static_cast<size_t>(f)] = uri_of(fs::path(path).filename().string());
    }
    spec.levels.push_back(uris);
  }
  write_file_atomically(gltf_path, sh::gltf_ibl_text(radiance, spec));
  written.push_back(gltf_path);
  return written;
}

}  // namespace ibl::engine
