#include "iblkit/sh/export.h"

#include <cmath>

#include <fmt/format.h>

#include "iblkit/core/enum_names.h"
#include "iblkit/core/error.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/rotate.h"

namespace ibl::sh {

namespace {

// K_i of the 9 basis polynomials p_i (basis.h): Y_i = K_i p_i.
//   K_0 = 1/(2√π) = 0.282095, K_1..3 = √3/(2√π) = 0.488603, K_4,5,7 = √15/(2√π) = 1.092548,
//   K_6 = √5/(4√π) = 0.315392, K_8 = √15/(4√π) = 0.546274.
double poly_constant(int i) {
  const double sp = std::sqrt(kPi);
  switch (i) {
    case 0:
      return 0.5 / sp;
    case 1:
    case 2:
    case 3:
      return std::sqrt(3.0) / (2 * sp);
    case 4:
    case 5:
    case 7:
      return std::sqrt(15.0) / (2 * sp);
    case 6:
      return std::sqrt(5.0) / (4 * sp);
    default:
      return std::sqrt(15.0) / (4 * sp);
  }
}
// Band and order of coefficient i < 9.
int band_of(int i) { return i == 0 ? 0 : (i < 4 ? 1 : 2); }
int order_of(int i) { return i - band_of(i) * (band_of(i) + 1); }

}  // namespace

namespace {
constexpr EnumName<ExportFormat> kExportFormatNames[] = {{ExportFormat::Iblkit, "iblkit"},
                                                         {ExportFormat::ThreeJs, "threejs"},
                                                         {ExportFormat::Filament, "filament"},
                                                         {ExportFormat::Gltf, "gltf"}};
}  // namespace

std::string export_format_name(ExportFormat f) { return name_of(kExportFormatNames, f); }
ExportFormat parse_export_format(const std::string& name) {
  return parse_enum(kExportFormatNames, name, "SH export format");
}

Coeffs to_threejs(const Coeffs& radiance) { return radiance.resized(3); }

Mat3 filament_from_iblkit() { return Mat3::rows({0, 0, -1}, {0, 1, 0}, {1, 0, 0}); }

Mat3 filament_frame(sphere::MappingKind k) {
  using K = sphere::MappingKind;
  if (k == K::CubeHCross || k == K::CubeVCross || k == K::CubeStrip)
    return Mat3::rows({-1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  return filament_from_iblkit();
}

Coeffs to_filament(const Coeffs& radiance, const Mat3& frame) {
  Coeffs c = rotate(radiance.resized(3), frame);
  auto a = clamped_cosine_zh(3);
  for (int i = 0; i < 9; ++i) c.c[i] *= a[band_of(i)] / kPi * poly_constant(i);
  return c;
}

Coeffs from_filament(const Coeffs& f, const Mat3& frame) {
  Coeffs c = f.resized(3);
  auto a = clamped_cosine_zh(3);
  for (int i = 0; i < 9; ++i) c.c[i] *= kPi / (a[band_of(i)] * poly_constant(i));
  return rotate(c, frame.transposed());
}

Coeffs to_gltf(const Coeffs& radiance) {
  Coeffs c = irradiance(radiance.resized(3));
  for (int i = 0; i < 9; ++i)
    if (order_of(i) % 2 != 0) c.c[i] = -c.c[i];
  return c;
}

Coeffs from_gltf(const Coeffs& g) {
  Coeffs c = g.resized(3);
  auto a = clamped_cosine_zh(3);
  for (int i = 0; i < 9; ++i) c.c[i] *= (order_of(i) % 2 != 0 ? -1.0 : 1.0) / a[band_of(i)];
  return c;
}

std::string export_text(const Coeffs& radiance, ExportFormat f, const Mat3& filament_frame) {
  radiance.validate("SH coefficients");
  switch (f) {
    case ExportFormat::Iblkit:
      return to_json_text(radiance);
    case ExportFormat::ThreeJs: {
      Coeffs c = to_threejs(radiance);
      nlohmann::json arr = nlohmann::json::array();
      for (const Vec3& v : c.c) {
        arr.push_back(v.x);
        arr.push_back(v.y);
        arr.push_back(v.z);
      }
      return nlohmann::json{{"type", "SphericalHarmonics3"}, {"coefficients", arr}}.dump(2) + "\n";
    }
    case ExportFormat::Filament: {
      Coeffs c = to_filament(radiance, filament_frame);
      std::string s;
      for (int i = 0; i < 9; ++i)
        s += fmt::format("({:18.15f}, {:18.15f}, {:18.15f}); // L{}{}, irradiance, pre-scaled base\n", c.c[i].x,
                         c.c[i].y, c.c[i].z, band_of(i), order_of(i));
      return s;
    }
    case ExportFormat::Gltf:
      return gltf_ibl_text(radiance);
  }
  return {};
}

std::string gltf_ibl_text(const Coeffs& radiance, const GltfSpecular& specular) {
  radiance.validate("SH coefficients");
  Coeffs c = to_gltf(radiance);
  nlohmann::json arr = nlohmann::json::array();
  for (const Vec3& v : c.c) arr.push_back({v.x, v.y, v.z});
  nlohmann::json light = {
      {"name", "iblkit"}, {"intensity", 1.0}, {"rotation", {0.0, 0.0, 0.0, 1.0}}, {"irradianceCoefficients", arr}};
  nlohmann::json doc = {
      {"asset", {{"version", "2.0"}, {"generator", "iblkit sh"}}},
      {"extensionsUsed", {"EXT_lights_image_based"}},
      {"scene", 0},
      {"scenes", {{{"name", "iblkit"}, {"extensions", {{"EXT_lights_image_based", {{"light", 0}}}}}}}}};
  if (!specular.levels.empty()) {
    if (specular.size < 1 || (specular.size & (specular.size - 1)) != 0)
      fail(ErrorKind::Value, "EXT_lights_image_based: specular image size {} must be a power of two", specular.size);
    if (specular.levels.size() > 31)
      fail(ErrorKind::Value, "EXT_lights_image_based: {} specular levels (at most 31)", specular.levels.size());
    nlohmann::json images = nlohmann::json::array(), levels = nlohmann::json::array();
    for (const auto& faces : specular.levels) {
      nlohmann::json idx = nlohmann::json::array();
      for (const std::string& uri : faces) {
        if (uri.empty()) fail(ErrorKind::Value, "EXT_lights_image_based: a specular face image has no URI");
        idx.push_back(images.size());
        images.push_back({{"uri", uri}, {"mimeType", "image/png"}});
      }
      levels.push_back(idx);
    }
    light["specularImageSize"] = specular.size;
    light["specularImages"] = levels;
    doc["images"] = images;
  }
  doc["extensions"] = {{"EXT_lights_image_based", {{"lights", {light}}}}};
  return doc.dump(2) + "\n";
}

}  // namespace ibl::sh
