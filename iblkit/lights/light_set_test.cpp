#include "iblkit/lights/light_set.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/lights/gltf.h"

namespace ibl::lights {
namespace {

LightSet sample_set() {
  LightSet s;
  s.method = "median-cut";
  s.lights = {{normalize(Vec3{0.2, 0.9, 0.1}), {3, 2, 1}, 0.01},
              {{0, -1, 0}, {0.5, 0.5, 0.5}, 2.0},
              {{0, 0, -1}, {0, 0, 1}, 0.5}};
  return s;
}

TEST(LightsJson, RoundTrip) {
  constexpr double kExact = 1e-15;  // JSON numbers keep doubles exactly (17 significant digits)
  auto s = sample_set();
  auto j = to_json(s);
  EXPECT_EQ(j["format"], "iblkit.lights/1");
  auto back = from_json(nlohmann::json::parse(j.dump()));
  ASSERT_EQ(back.lights.size(), s.lights.size());
  for (size_t i = 0; i < s.lights.size(); ++i) {
    EXPECT_NEAR(dot(back.lights[i].direction, s.lights[i].direction), 1, kExact);
    EXPECT_NEAR(back.lights[i].irradiance.x, s.lights[i].irradiance.x, kExact);
    EXPECT_NEAR(back.lights[i].solid_angle, s.lights[i].solid_angle, kExact);
    EXPECT_NEAR(j["lights"][i]["radiance"][0].get<double>(), s.lights[i].irradiance.x / s.lights[i].solid_angle,
                kExact * 1e3);
  }
  EXPECT_EQ(back.method, "median-cut");
  EXPECT_FALSE(back.origin);
  EXPECT_FALSE(back.lights[0].position);
  EXPECT_FALSE(j.contains("origin"));
}

TEST(LightsJson, LocalisedPositionsAndOriginRoundTrip) {
  constexpr double kExact = 1e-15;  // JSON numbers keep doubles exactly (17 significant digits)
  auto s = sample_set();
  s.origin = Vec3{1.5, -0.25, 3};
  s.lights[1].position = Vec3{0.125, 2, -7};
  auto back = from_json(nlohmann::json::parse(to_json(s).dump()));
  ASSERT_TRUE(back.origin);
  EXPECT_NEAR(back.origin->x, 1.5, kExact);
  EXPECT_NEAR(back.origin->z, 3, kExact);
  EXPECT_FALSE(back.lights[0].position);
  ASSERT_TRUE(back.lights[1].position);
  EXPECT_NEAR(back.lights[1].position->y, 2, kExact);
  EXPECT_NEAR(back.lights[1].position->z, -7, kExact);
  EXPECT_THROW(
      from_json(nlohmann::json::parse(
          R"({"format":"iblkit.lights/1","origin":[1,2],"lights":[{"direction":[0,1,0],"irradiance":[1,1,1]}]})")),
      Error);
}

TEST(LightsJson, BadFilesNameTheField) {
  auto bad = [](const std::string& text, const std::string& needle) {
    try {
      from_json(nlohmann::json::parse(text), "x.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  bad(R"({"format":"iblkit.sh/1"})", "not an iblkit.lights/1");
  bad(R"({"format":"iblkit.lights/1","lights":[{"direction":[0,1],"irradiance":[1,1,1]}]})", "direction");
  bad(R"({"format":"iblkit.lights/1","lights":[{"direction":[0,0,0],"irradiance":[1,1,1]}]})", "zero vector");
  bad(R"({"format":"iblkit.lights/1","lights":[{"direction":[0,1,0],"irradiance":[1,-1,1]}]})", "negative");
  bad(R"({"format":"iblkit.lights/1","lights":[]})", "empty");
  EXPECT_THROW(read_lights("/nonexistent/lights.json"), Error);
}

TEST(LightsShadows, RankAndMerge) {
  auto s = sample_set();
  rank_for_shadows(s);
  // Radiance Y(E)/Ω: (3,2,1) 2.15/0.01 = 215, grey 0.5/2 = 0.25, blue 0.0721/0.5 = 0.144.
  EXPECT_EQ(s.lights[0].irradiance.x, 3);
  EXPECT_EQ(s.lights[1].irradiance.x, 0.5);
  EXPECT_EQ(s.lights[2].irradiance.z, 1);
  LightSet m;
  m.lights = {{{0, 1, 0}, {1, 1, 1}, 0.1}, {normalize(Vec3{0.05, 1, 0}), {1, 1, 1}, 0.1}, {{1, 0, 0}, {1, 1, 1}, 0.1}};
  EXPECT_EQ(merge_close_lights(m, 10 * kPi / 180), 1);
  ASSERT_EQ(m.lights.size(), 2u);
  EXPECT_NEAR(m.lights[0].irradiance.x, 2, 1e-12);
  EXPECT_NEAR(m.lights[0].solid_angle, 0.2, 1e-12);
}

TEST(LightsGltf, DirectionalLightsPointAtTheProbe) {
  constexpr double kExact = 1e-12;
  auto s = sample_set();
  auto g = to_gltf(s, {2.0});
  EXPECT_EQ(g["asset"]["version"], "2.0");
  EXPECT_EQ(g["extensionsUsed"][0], "KHR_lights_punctual");
  const auto& lights = g["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 3u);
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const auto& l = lights[i];
    EXPECT_EQ(l["type"], "directional");
    // colour in [0,1] and colour × intensity = lux_per_unit · E
    for (int c = 0; c < 3; ++c) {
      double col = l["color"][c].get<double>();
      EXPECT_GE(col, 0);
      EXPECT_LE(col, 1);
      EXPECT_NEAR(col * l["intensity"].get<double>(), 2.0 * s.lights[i].irradiance[c], kExact);
    }
    // The node's rotation takes the light's local −Z onto −direction (the light travels towards the probe).
    const auto& q = g["nodes"][i]["rotation"];
    double x = q[0], y = q[1], z = q[2], w = q[3];
    EXPECT_NEAR(x * x + y * y + z * z + w * w, 1, kExact);
    // Rotate (0,0,−1) by q: v' = v + 2w(q×v) + 2 q×(q×v).
    Vec3 qv{x, y, z}, v{0, 0, -1};
    Vec3 t = cross(qv, v) * 2.0;
    Vec3 r = v + t * w + cross(qv, t);
    EXPECT_NEAR(dot(r, -s.lights[i].direction), 1, kExact) << i;
    EXPECT_EQ(g["nodes"][i]["extensions"]["KHR_lights_punctual"]["light"], i);
  }
  EXPECT_EQ(g["scenes"][0]["nodes"].size(), 3u);
  EXPECT_THROW(to_gltf(s, {0.0}), Error);
}

}  // namespace
}  // namespace ibl::lights
