#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "iblkit/core/error.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/io/image_io.h"
#include "iblkit/render/lighting_io.h"
#include "iblkit/render/objects.h"

namespace ibl::render {
namespace {

namespace fs = std::filesystem;

// A file in a fresh temporary folder, holding `text`.
std::string temp_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("iblkit_lighting_io_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& path, const LightingReadDesc& desc = {}) {
  Lighting L;
  try {
    read_lighting(path, desc, &L);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// iblkit.sh/1 goes through sh::coeffs_from_json: the coefficients come back as written, and the
// checks of that reader hold (bands in range, a number per channel).
TEST(RenderLightingIo, ShFileIsCheckedAsEverywhere) {
  Lighting L;
  std::string kind;
  read_lighting(
      temp_file("env.json",
                R"({"format":"iblkit.sh/1","bands":2,"coefficients":[[1,2,3],[0,0.5,0],[0,0,0],[-0.25,0,0]]})"),
      {}, &L, &kind);
  ASSERT_TRUE(L.environment);
  EXPECT_EQ(L.environment->bands, 2);
  EXPECT_EQ(L.environment->c[0].y, 2.0);
  EXPECT_EQ(L.environment->c[3].x, -0.25);
  EXPECT_EQ(kind, "SH environment, 2 bands");
  EXPECT_NE(
      error_of(temp_file("zero.json", R"({"format":"iblkit.sh/1","bands":0,"coefficients":[]})")).find("\"bands\""),
      std::string::npos);
  EXPECT_NE(error_of(temp_file("null.json", R"({"format":"iblkit.sh/1","bands":1,"coefficients":[[1,null,3]]})"))
                .find("coefficient 0"),
            std::string::npos);
  EXPECT_NE(error_of(temp_file("other.json", R"({"format":"iblkit.scene/1"})")).find("expected iblkit.lights/1"),
            std::string::npos);
}

// A light set: a light with a position in a set with an origin is a point light of intensity
// E·|q − o|², the others directional; the first `shadows` cast shadows unless a light says itself.
TEST(RenderLightingIo, LightSetBecomesPointAndDirectionalLights) {
  const std::string path =
      temp_file("lights.json", R"({"format":"iblkit.lights/1","method":"test","origin":[0,1,0],"lights":[
    {"direction":[0,1,0],"irradiance":[1,2,3],"solid_angle":0.1,"position":[0,3,0]},
    {"direction":[2,0,0],"irradiance":[1,1,1],"solid_angle":0.1,"shadow":true},
    {"direction":[0,0,1],"irradiance":[0.5,0.5,0.5],"solid_angle":0.1},
    {"direction":[0,0,-1],"irradiance":[0.5,0.5,0.5],"solid_angle":0.1,"shadow":false}]})");
  LightingReadDesc desc;
  desc.shadows = 1;
  Lighting L;
  std::string kind;
  read_lighting(path, desc, &L, &kind);
  ASSERT_EQ(L.point_lights.size(), 1u);
  ASSERT_EQ(L.lights.size(), 3u);
  EXPECT_EQ(L.point_lights[0].position.y, 3.0);
  EXPECT_EQ(L.point_lights[0].intensity.z, 12.0);  // 3 W/m² at 2 m
  EXPECT_TRUE(L.point_lights[0].shadow);           // first in priority order
  EXPECT_EQ(L.lights[0].direction.x, 1.0);         // unit
  EXPECT_TRUE(L.lights[0].shadow);                 // says so itself
  EXPECT_FALSE(L.lights[1].shadow);
  EXPECT_FALSE(L.lights[2].shadow);
  EXPECT_EQ(kind, "1 point lights and 3 directional lights");
  EXPECT_NE(error_of(temp_file("bad_shadow.json", R"({"format":"iblkit.lights/1","lights":[
    {"direction":[0,1,0],"irradiance":[1,1,1],"shadow":"yes"}]})"))
                .find("\"shadow\""),
            std::string::npos);
}

// An SH grid comes as it was written; a constant probe image projects to c00 = √(4π)·L and, with a
// glossy exponent, brings its prefiltered map (of the same constant).
TEST(RenderLightingIo, GridAndProbeImage) {
  constexpr double kProjectTol = 1e-4;     // lat-long quadrature of a constant: exact up to float pixels
  constexpr double kQuadratureTol = 5e-3;  // the prefilter's midpoint rule (as Prefilter.ConstantSkyGivesItsRadiance)
  ilf::GridDesc gd;
  gd.nx = 2;
  gd.ny = 3;
  gd.nz = 2;
  gd.volume = {{0, 0, 0}, {1, 2, 1}};
  ilf::SHGrid g(gd, 2);
  for (size_t i = 0; i < g.data().size(); ++i) g.data()[i] = static_cast<float>(i);
  const std::string grid_path = temp_file("g.shgrid", "");
  ilf::write_shgrid(grid_path, g);
  Lighting L;
  std::string kind;
  read_lighting(grid_path, {}, &L, &kind);
  ASSERT_TRUE(L.grid);
  EXPECT_EQ(L.grid->data(), g.data());
  EXPECT_EQ(L.grid->grid().volume.max.y, 2.0);
  EXPECT_EQ(kind, "SH grid 2x3x2, 2 bands");

  const std::string probe = (fs::path(temp_file("probe.exr", "")).parent_path() / "probe.exr").string();
  io::write_image(probe, Image(64, 32, 3, 0.5f));
  LightingReadDesc desc;
  desc.bands = 3;
  desc.glossy_exponent = 10;
  Lighting P;
  read_lighting(probe, desc, &P, &kind);
  ASSERT_TRUE(P.environment);
  EXPECT_EQ(P.environment->bands, 3);
  EXPECT_NEAR(P.environment->c[0].x, 0.5 * std::sqrt(kFourPi), kProjectTol);
  ASSERT_EQ(P.glossy_maps.size(), 1u);
  EXPECT_NEAR(P.glossy_maps[0].latlong.at(3, 5, 1), 0.5, 0.5 * kQuadratureTol);
  EXPECT_NE(kind.find("probe projected to 3 SH bands, glossy from a prefiltered"), std::string::npos) << kind;
}

// The scene objects: sized and placed, with normals; a grid's volume is inside or not.
TEST(RenderObjects, SizedPlacedAndCheckedAgainstTheGrid) {
  constexpr double kTessTol = 1e-9;  // the UV sphere's poles lie exactly on the radius
  geometry::TriMesh s = make_object({.scene = "sphere", .size = 0.5, .at = {1, 2, 3}});
  ASSERT_TRUE(s.has_normals());
  Vec3 lo, hi;
  s.bounds(&lo, &hi);
  EXPECT_NEAR(hi.y, 2.25, kTessTol);
  EXPECT_NEAR(lo.y, 1.75, kTessTol);
  EXPECT_THROW(make_object({.scene = "blob", .size = 0}), Error);
  const std::string obj = temp_file("tri.obj", "v 0 0 0\nv 2 0 0\nv 0 4 0\nf 1 2 3\n");
  geometry::TriMesh m = make_object({.scene = obj, .size = 1, .at = {0, 1, 0}});
  m.bounds(&lo, &hi);
  EXPECT_NEAR(hi.y - lo.y, 1.0, kTessTol);  // the largest extent (y: 4 m) scaled to 1 m
  EXPECT_NEAR(lo.y + hi.y, 2.0, kTessTol);  // centred on `at`
  ASSERT_TRUE(m.has_normals());
  Lighting L;
  EXPECT_FALSE(reaches_outside_grid(L, m));
  ilf::GridDesc gd;
  gd.volume = {{-1, 0.5, -1}, {1, 1.5, 1}};
  L.grid.emplace(gd, 1);
  EXPECT_FALSE(reaches_outside_grid(L, m));  // on the faces is inside
  m.transform(1.0, {0, 0.01, 0});
  EXPECT_TRUE(reaches_outside_grid(L, m));
}

}  // namespace
}  // namespace ibl::render
