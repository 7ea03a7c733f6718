#include "iblkit/sh/export.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/sh/convolve.h"

namespace ibl::sh {
namespace {

constexpr double kExportTol = 1e-12;  // conversions are a few multiplications

Coeffs some_radiance() {
  Coeffs c(4);  // 4 bands: exports keep the first 3
  for (int k = 0; k < 16; ++k) c.c[k] = {1.0 / (k + 1), std::sin(k + 0.5), k == 0 ? 2.0 : 0.05 * k};
  return c;
}

// The 9 polynomials the engines evaluate: (1, y, z, x, yx, yz, 3z²−1, zx, x²−y²).
void polys(Vec3 n, double* p) {
  const double v[9] = {1, n.y, n.z, n.x, n.y * n.x, n.y * n.z, 3 * n.z * n.z - 1, n.z * n.x, n.x * n.x - n.y * n.y};
  for (int i = 0; i < 9; ++i) p[i] = v[i];
}

const Vec3 kNormals[] = {Vec3{0, 1, 0}, Vec3{0.6, 0, -0.8}, Vec3{-0.48, 0.6, 0.64}};

// three.js SphericalHarmonics3.getAt: Σ c_i K_i p_i with K = 0.282095, 0.488603 (×3), 1.092548 (×2),
// 0.315392, 1.092548, 0.546274 — radiance.
TEST(ShExport, ThreeJsEvaluatesToRadiance) {
  const double K[9] = {0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392, 1.092548, 0.546274};
  constexpr double kThreeConstTol = 1e-5;  // three.js stores its constants to 6 digits
  Coeffs r = some_radiance(), t = to_threejs(r);
  for (Vec3 n : kNormals) {
    double p[9], s = 0;
    polys(n, p);
    for (int i = 0; i < 9; ++i) s += t.c[i].y * K[i] * p[i];
    EXPECT_NEAR(s, r.resized(3).evaluate(n).y, kThreeConstTol);
  }
}

// Filament's shader: Irradiance_SphericalHarmonics(n_f) = Σ s_i p_i(n_f) = E(n)/π, where n_f = M n
// is the normal in cmgen's frame (filament_from_iblkit).
TEST(ShExport, FilamentShaderGivesIrradianceOverPi) {
  Coeffs r = some_radiance(), f = to_filament(r);
  for (Vec3 n : kNormals) {
    double p[9];
    polys(filament_from_iblkit() * n, p);
    Vec3 s;
    for (int i = 0; i < 9; ++i) s += f.c[i] * p[i];
    Vec3 e = irradiance_at(r.resized(3), n) / kPi;
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(s[ch], e[ch], kExportTol);
  }
  Coeffs back = from_filament(f);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(back.c[i].z, r.c[i].z, 1e-9);  // through two SH rotations
  std::string txt = export_text(r, ExportFormat::Filament);
  EXPECT_EQ(std::count(txt.begin(), txt.end(), '\n'), 9);
  EXPECT_NE(txt.find("// L2-2, irradiance, pre-scaled base"), std::string::npos);
}

// Babylon.js (EXT_lights_image_based's reference loader) evaluates Σ E_i K_i^CS p_i with the
// Condon–Shortley signs (−, +, − on band 1; +, −, +, −, + on band 2): that must be E(n).
TEST(ShExport, GltfIrradianceInBabylonBasis) {
  const double sp = std::sqrt(kPi);
  const double K[9] = {0.5 / sp,
                       -std::sqrt(3.0) / (2 * sp),
                       std::sqrt(3.0) / (2 * sp),
                       -std::sqrt(3.0) / (2 * sp),
                       std::sqrt(15.0) / (2 * sp),
                       -std::sqrt(15.0) / (2 * sp),
                       std::sqrt(5.0) / (4 * sp),
                       -std::sqrt(15.0) / (2 * sp),
                       std::sqrt(15.0) / (4 * sp)};
  Coeffs r = some_radiance(), g = to_gltf(r);
  for (Vec3 n : kNormals) {
    double p[9];
    polys(n, p);
    Vec3 s;
    for (int i = 0; i < 9; ++i) s += g.c[i] * (K[i] * p[i]);
    Vec3 e = irradiance_at(r.resized(3), n);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(s[ch], e[ch], kExportTol);
  }
  Coeffs back = from_gltf(g);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(back.c[i].x, r.c[i].x, kExportTol);
  auto j = nlohmann::json::parse(export_text(r, ExportFormat::Gltf));
  EXPECT_EQ(j["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"].size(), 9u);
}

TEST(ShJson, RoundTripAndBadInput) {
  Coeffs r = some_radiance();
  std::string path = (std::filesystem::temp_directory_path() / "iblkit_sh_test.json").string();
  write_coeffs(path, r);
  Coeffs back = read_coeffs(path);
  ASSERT_EQ(back.bands, 4);
  for (int k = 0; k < 16; ++k) EXPECT_EQ(back.c[k].y, r.c[k].y);  // %.17g round trip is exact
  std::remove(path.c_str());
  auto bad = [](const char* text) { return coeffs_from_json(nlohmann::json::parse(text), "test"); };
  EXPECT_THROW(bad(R"({"format":"other","bands":1,"coefficients":[[1,1,1]]})"), Error);
  EXPECT_THROW(bad(R"({"format":"iblkit.sh/1","bands":2,"coefficients":[[1,1,1]]})"), Error);
  EXPECT_THROW(bad(R"({"format":"iblkit.sh/1","bands":0,"coefficients":[]})"), Error);
  EXPECT_THROW(bad(R"({"format":"iblkit.sh/1","bands":1,"coefficients":[[1,"a",1]]})"), Error);
  EXPECT_THROW(read_coeffs("/nonexistent/sh.json"), Error);
  EXPECT_THROW(parse_export_format("unity"), Error);
  auto three = nlohmann::json::parse(export_text(r, ExportFormat::ThreeJs));
  EXPECT_EQ(three["coefficients"].size(), 27u);
}

}  // namespace
}  // namespace ibl::sh

namespace ibl::sh {

// A whole glTF document: asset, extensionsUsed, scene 0 → light 0; specular images listed once each
// and referenced level by level, face by face.
TEST(ShExport, GltfDocumentWithSpecularImages) {
  Coeffs r(3);
  r.c[0] = {1, 1, 1};
  GltfSpecular spec;
  spec.size = 64;
  for (int m = 0; m < 2; ++m) {
    std::array<std::string, 6> faces;
    for (int f = 0; f < 6; ++f) faces[f] = "spec_m" + std::to_string(m) + "_" + std::to_string(f) + ".png";
    spec.levels.push_back(faces);
  }
  auto j = nlohmann::json::parse(gltf_ibl_text(r, spec));
  EXPECT_EQ(j["asset"]["version"], "2.0");
  EXPECT_EQ(j["extensionsUsed"][0], "EXT_lights_image_based");
  EXPECT_EQ(j["scenes"][j["scene"].get<int>()]["extensions"]["EXT_lights_image_based"]["light"], 0);
  const auto& light = j["extensions"]["EXT_lights_image_based"]["lights"][0];
  EXPECT_EQ(light["specularImageSize"], 64);
  ASSERT_EQ(light["specularImages"].size(), 2u);
  EXPECT_EQ(light["specularImages"][1][5], 11);
  EXPECT_EQ(j["images"][11]["uri"], "spec_m1_5.png");
  EXPECT_FALSE(
      nlohmann::json::parse(export_text(r, ExportFormat::Gltf))["extensions"]["EXT_lights_image_based"]["lights"][0]
          .contains("specularImages"));
  spec.size = 48;
  EXPECT_THROW(gltf_ibl_text(r, spec), Error);
}

}  // namespace ibl::sh
