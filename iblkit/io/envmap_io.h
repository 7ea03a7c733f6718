// Environment maps from files: one image in any mapping, or a folder of six cube faces
// (px nx py ny pz nz, any image extension), assembled into a horizontal cross.
// It lives in io/, above sphere/ (docs/architecture.md): reading a map needs the image reader and
// sphere/'s mapping detection, and sphere/ stays free of file I/O and OpenImageIO.
#pragma once
#include <optional>
#include <string>

#include "iblkit/io/image_io.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::io {

struct EnvReadDesc {
  std::optional<sphere::MappingKind> mapping;  // override detection from the shape / name
  double dead_angle_deg = 0.0;                 // mirror balls: the unusable cone behind the ball
  bool sanitize = false;                       // replace NaN/Inf/negative by 0 (see ReadDesc)
};

sphere::EnvMap read_envmap(const std::string& path, const EnvReadDesc& desc = {}, ReadReport* report = nullptr);

// Writes six face images px.EXT … nz.EXT of a cube-layout env map into folder `dir`.
void write_cube_faces(const std::string& dir, const sphere::EnvMap& cube, const std::string& ext = ".exr");

}  // namespace ibl::io
