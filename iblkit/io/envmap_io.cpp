#include "iblkit/io/envmap_io.h"

#include <array>
#include <filesystem>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"

namespace ibl::io {

namespace fs = std::filesystem;
using sphere::EnvMap;
using sphere::Mapping;
using sphere::MappingKind;

namespace {
constexpr std::array<const char*, 6> kFaceNames = {"px", "nx", "py", "ny", "pz", "nz"};
}

EnvMap read_envmap(const std::string& path, const EnvReadDesc& desc, ReadReport* report) {
  std::error_code ec;
  ReadDesc rd{desc.sanitize, 0};
  if (fs::is_directory(path, ec)) {
    std::array<Image, 6> faces;
    int sanitized = 0;
    for (int f = 0; f < 6; ++f) {
      std::string found;
      for (const auto& e : fs::directory_iterator(path))
        if (e.path().stem() == kFaceNames[f]) found = e.path().string();
      if (found.empty())
        fail(ErrorKind::Io, "{}: folder has no cube face '{}.*' (expected px nx py ny pz nz)", path, kFaceNames[f]);
      ReadReport r;
      faces[f] = read_image(found, rd, &r);
      sanitized += r.sanitized;
      if (report) *report = r;
      if (faces[f].width() != faces[f].height())
        fail(ErrorKind::Value, "{}: cube face is {}x{}, not square", found, faces[f].width(), faces[f].height());
      if (f > 0 && (faces[f].width() != faces[0].width() || faces[f].channels() != faces[0].channels()))
        fail(ErrorKind::Value, "{}: cube face is {}x{}x{} but {} is {}x{}x{}", found, faces[f].width(),
             faces[f].height(), faces[f].channels(), kFaceNames[0], faces[0].width(), faces[0].height(),
             faces[0].channels());
    }
    if (report) report->sanitized = sanitized;
    int n = faces[0].width(), nc = faces[0].channels();
    Mapping m(MappingKind::CubeHCross, 4 * n, 3 * n);
    Image cross(4 * n, 3 * n, nc);
    for (int f = 0; f < 6; ++f) {
      double px, py;
      // The cell of face f: map its centre direction.
      m.to_pixel(normalize(sphere::cube_face_point(f, 0, 0)), &px, &py);
      int cx = static_cast<int>(px) / n, cy = static_cast<int>(py) / n;
      for (int y = 0; y < n; ++y)
        std::copy_n(faces[f].pixel(0, y), static_cast<size_t>(n) * nc, cross.pixel(cx * n, cy * n + y));
    }
    return EnvMap(std::move(cross), m);
  }
  Image img = read_image(path, rd, report);
  if (img.channels() == 2 || img.channels() > 4)
    fail(ErrorKind::Value, "{}: {} channels; a probe needs 1 (grey), 3 (RGB) or 4 (RGBA)", path, img.channels());
  return EnvMap::from_image(std::move(img), desc.mapping, fs::path(path).filename().string(), desc.dead_angle_deg);
}

void write_cube_faces(const std::string& dir, const EnvMap& cube, const std::string& ext) {
  MappingKind k = cube.mapping.kind();
  if (k != MappingKind::CubeHCross && k != MappingKind::CubeVCross && k != MappingKind::CubeStrip)
    fail(ErrorKind::Value, "write_cube_faces needs a cube layout, got {}", sphere::mapping_name(k));
  ibl::make_output_folders(fs::path(dir).string());
  int n = cube.mapping.face_size();
  for (int f = 0; f < 6; ++f) {
    Image face(n, n, cube.image.channels());
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        double s = 2.0 * (x + 0.5) / n - 1, t = 2.0 * (y + 0.5) / n - 1;
        double px, py;
        cube.mapping.to_pixel(normalize(sphere::cube_face_point(f, s, t)), &px, &py);
        std::copy_n(cube.image.pixel(static_cast<int>(px), static_cast<int>(py)), cube.image.channels(),
                    face.pixel(x, y));
      }
    write_image((fs::path(dir) / (std::string(kFaceNames[f]) + ext)).string(), face);
  }
}

}  // namespace ibl::io
