// io/ and sphere/: image files, mappings, resampling between them, tone mapping.
#include "common.h"

#include <cmath>

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/sphere/envmap.h"

namespace iblpy {

namespace {

using ibl::sphere::MappingKind;

// Output size from a "size" as `iblkit convert --size` reads it: lat-long height, cube face edge,
// disc/octahedral diameter; 0 keeps the input's pixel count roughly.
ibl::sphere::Mapping output_mapping(MappingKind k, int size, int in_w, int in_h) {
  if (size == 0) {
    double pixels = static_cast<double>(in_w) * in_h;
    double per = k == MappingKind::LatLong                                                                       ? 2
                 : (k == MappingKind::CubeHCross || k == MappingKind::CubeVCross || k == MappingKind::CubeStrip) ? 6
                                                                                                                 : 1;
    size = std::max(1, static_cast<int>(std::sqrt(pixels / per)));
  }
  if (size < 1 || size > 16384) ibl::fail(ibl::ErrorKind::Value, "size must be in 1..16384 (got {})", size);
  switch (k) {
    case MappingKind::LatLong:
      return {k, 2 * size, size};
    case MappingKind::CubeHCross:
      return {k, 4 * size, 3 * size};
    case MappingKind::CubeVCross:
      return {k, 3 * size, 4 * size};
    case MappingKind::CubeStrip:
      return {k, 6 * size, size};
    default:
      return {k, size, size};
  }
}

}  // namespace

void init_io(py::module_& m) {
  m.def(
      "read_image",
      [](const std::string& path, bool sanitize, int max_channels) {
        ibl::Image img;
        {
          py::gil_scoped_release nogil;
          ibl::io::ReadDesc d;
          d.sanitize = sanitize;
          d.max_channels = max_channels;
          img = ibl::io::read_image(path, d);
        }
        return to_array(std::move(img));
      },
      py::arg("path"), py::arg("sanitize") = false, py::arg("max_channels") = 0,
      R"doc(Reads an image file (.exr, .hdr, .pfm, .png, .jpg, .tif, … as `iblkit` reads them) into a
float32 array of shape (H, W, C), linear light (8-bit sRGB files are decoded to linear).

sanitize: replace NaN/Inf/negative pixels by 0 instead of raising InvalidValue.
max_channels: keep at most this many channels (3 drops alpha); 0 keeps all.
Raises IoError for a missing or unreadable file, FormatError for a corrupt one.)doc");

  m.def(
      "write_image",
      [](const std::string& path, py::handle img, bool half) {
        ibl::Image im = to_image(img, "write_image: img");
        py::gil_scoped_release nogil;
        ibl::io::write_image(path, im, {half});
      },
      py::arg("path"), py::arg("img"), py::arg("half") = false,
      R"doc(Writes an (H, W, C) or (H, W) float array as an image; the format follows the extension.
.exr keeps float32 (half=True: 16-bit halves); .png/.jpg are sRGB-encoded 8 bits clamped to [0, 1]
(tone map HDR content first, see tonemap). Written atomically (a temporary file renamed into place).)doc");

  m.def(
      "convert",
      [](py::handle img, const std::string& src, const std::string& dst, int size, py::object rotation,
         double dead_angle, int max_supersampling) {
        ibl::Image in = to_checked_image(img, "convert: img");
        MappingKind k = ibl::sphere::parse_mapping(dst, "dst");
        ibl::sphere::ResampleDesc rd;
        if (!rotation.is_none()) rd.rotation = to_mat3(rotation, "convert: rotation");
        rd.max_supersampling = max_supersampling;
        if (max_supersampling < 1 || max_supersampling > 64)
          ibl::fail(ibl::ErrorKind::Value, "max_supersampling must be in 1..64 (got {})", max_supersampling);
        ibl::sphere::Mapping sm = mapping_of(src, in.width(), in.height(), dead_angle);
        ibl::sphere::Mapping out = output_mapping(k, size, in.width(), in.height());
        ibl::require_allocation(fmt::format("convert: a {} map of {}x{} pixels", dst, out.width(), out.height()),
                                double(out.width()) * out.height(), 3 * 3 * sizeof(float) + sizeof(double),
                                "choose a smaller size");
        ibl::Image res;
        {
          py::gil_scoped_release nogil;
          ibl::sphere::EnvMap env(std::move(in), sm);
          res = ibl::sphere::resample(env, out, rd);
        }
        return to_array(std::move(res));
      },
      py::arg("img"), py::arg("src") = "latlong", py::arg("dst") = "latlong", py::arg("size") = 0,
      py::arg("rotation") = py::none(), py::arg("dead_angle") = 0.0, py::arg("max_supersampling") = 8,
      R"doc(Resamples an environment map from mapping `src` into mapping `dst`, as `iblkit convert`.

Mappings: latlong, mirrorball, angular, hcross, vcross, cubestrip, octahedral ("auto" for src detects
it from the shape). size: lat-long height, cube face edge or disc/octahedral diameter of the output
(0 keeps the input's pixel count roughly). rotation: 3×3 matrix turning the environment (the output
direction d looks up the input at rotationᵀ·d). dead_angle: degrees of a mirror ball's unusable cone.
∫ L dω is preserved. Returns a float32 (H, W, 3) array.)doc");

  m.def(
      "detect_mapping",
      [](int width, int height, const std::string& name) {
        return ibl::sphere::mapping_name(ibl::sphere::detect_mapping(width, height, name));
      },
      py::arg("width"), py::arg("height"), py::arg("file_name") = "",
      "The mapping iblkit assumes for an image of this shape (and file name hints: angular, probe, ball, oct).");

  m.def(
      "solid_angles",
      [](const std::string& mapping, int width, int height, double dead_angle) {
        if (width < 1 || height < 1 || width > 65536 || height > 65536)
          ibl::fail(ibl::ErrorKind::Value, "solid_angles: size {}x{} outside 1..65536", width, height);
        ibl::sphere::Mapping mp = mapping_of(mapping, width, height, dead_angle);
        ibl::Image s;
        {
          py::gil_scoped_release nogil;
          s = ibl::sphere::solid_angle_image(mp);
        }
        return to_array(std::move(s), true);
      },
      py::arg("mapping"), py::arg("width"), py::arg("height"), py::arg("dead_angle") = 0.0,
      "Exact solid angle (sr) of every pixel of a mapping as an (H, W) float32 array; they sum to 4π.");

  m.def(
      "tonemap",
      [](py::handle img, double exposure, bool auto_exposure, double key, const std::string& curve) {
        ibl::Image in = to_checked_image(img, "tonemap: img");
        ibl::io::ToneMapDesc d;
        d.exposure_stops = exposure;
        d.auto_exposure = auto_exposure;
        d.key = key;
        if (curve == "aces")
          d.curve = ibl::io::ToneCurve::Aces;
        else if (curve == "reinhard")
          d.curve = ibl::io::ToneCurve::Reinhard;
        else if (curve == "clamp")
          d.curve = ibl::io::ToneCurve::Clamp;
        else
          ibl::fail(ibl::ErrorKind::Value, "tonemap: unknown curve '{}' (use aces, reinhard, clamp)", curve);
        ibl::Image out;
        {
          py::gil_scoped_release nogil;
          out = ibl::io::tonemap(in, d);
        }
        return to_array(std::move(out));
      },
      py::arg("img"), py::arg("exposure") = 0.0, py::arg("auto_exposure") = true, py::arg("key") = 0.18,
      py::arg("curve") = "aces",
      R"doc(Tone maps an HDR image into linear [0, 1] RGB (write it as .png for sRGB, or show it with
matplotlib after `** (1/2.2)`): auto exposure puts the median luminance on `key`, `exposure` adds stops.)doc");
}

}  // namespace iblpy
