#include "iblkit/engine/export.h"

#include <filesystem>

#include <fmt/format.h>

#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/export.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::engine {

namespace fs = std::filesystem;

namespace {
constexpr EnumName<EngineFrame> kFrameNames[] = {{EngineFrame::Iblkit, "iblkit"},
                                                 {EngineFrame::Filament, "filament"},
                                                 {EngineFrame::Iblkit, "threejs"},
                                                 {EngineFrame::Iblkit, "gltf"}};
constexpr const char* kFaceNames[6] = {"px", "nx", "py", "ny", "pz", "nz"};

std::string lower_ext(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}
void make_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail(ErrorKind::Io, "{}: cannot create the folder ({})", dir, ec.message());
}
}  // namespace

std::string engine_frame_name(EngineFrame f) { return name_of(kFrameNames, f); }
EngineFrame parse_engine_frame(const std::string& name) { return parse_enum(kFrameNames, name, "engine frame"); }
Mat3 frame_rotation(EngineFrame f, sphere::MappingKind k) {
  return f == EngineFrame::Filament ? sh::filament_frame(k) : Mat3::identity();
}

Image cube_face(const CubeChain& cube, int level, int face) {
  const int s = cube.size(level);
  return cube.levels[static_cast<size_t>(level)].crop(face * s, 0, s, s);
}

Ktx2Texture cube_ktx2(const CubeChain& cube) {
  Ktx2Texture t;
  t.vk_format = kVkFormatRgba16f;
  t.faces = 6;
  for (int m = 0; m < cube.count(); ++m) {
    std::vector<Image> faces;
    for (int f = 0; f < 6; ++f) faces.push_back(cube_face(cube, m, f));
    t.levels.push_back(std::move(faces));
  }
  return t;
}

void write_cube_faces(const std::string& dir, const CubeChain& cube) {
  make_dir(dir);
  for (int m = 0; m < cube.count(); ++m)
    for (int f = 0; f < 6; ++f)
      io::write_image((fs::path(dir) / fmt::format("m{}_{}.exr", m, kFaceNames[f])).string(), cube_face(cube, m, f));
}

void write_cube_latlongs(const std::string& dir, const CubeChain& cube) {
  make_dir(dir);
  for (int m = 0; m < cube.count(); ++m) {
    const int h = 2 * cube.size(m), w = 2 * h;
    sphere::Mapping ll(sphere::MappingKind::LatLong, w, h);
    Image out(w, h, 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        Vec3 d;
        ll.to_direction(x + 0.5, y + 0.5, &d);
        out.set_rgb(x, y, cube.sample(d, m));
      }
    io::write_image((fs::path(dir) / fmt::format("m{}.exr", m)).string(), out);
  }
}

void write_cube(const std::string& path, const Image& strip) {
  CubeChain one;
  one.levels.push_back(strip);
  if (lower_ext(path) == ".ktx2") return write_ktx2(path, cube_ktx2(one));
  make_dir(path);
  for (int f = 0; f < 6; ++f)
    io::write_image((fs::path(path) / fmt::format("{}.exr", kFaceNames[f])).string(), cube_face(one, 0, f));
}

void write_dfg(const std::string& path, const Image& table) {
  const std::string e = lower_ext(path);
  if (e == ".ktx2") {
    Ktx2Texture t;
    t.vk_format = kVkFormatRg16f;
    t.levels.push_back({table});
    return write_ktx2(path, t);
  }
  if (e == ".png") {
    io::WriteDesc wd;
    wd.data = true;
    return io::write_image(path, table, wd);
  }
  if (e == ".exr") return io::write_image(path, table);
  fail(ErrorKind::Value, "{}: the DFG table is written as .png, .exr or .ktx2", path);
}

}  // namespace ibl::engine
