#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/lab/capture.h"
#include "iblkit/lab/radiance.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"

namespace ibl::lab {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("iblkit_lab_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

TEST(LabScene, BuiltInScenesLoadAndAreLitInsideTheirVolume) {
  for (const char* name : {"low-scene1", "low-scene2", "t-corridor", "crypt"}) {
    Scene s = load_scene(name);
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.emitters.empty()) << name;
    CaptureDesc cd;
    cd.size = 16;
    Capture c = capture_probe(s, (s.volume_min + s.volume_max) * 0.5, cd);
    double lum = 0;
    for (int y = 0; y < c.radiance.height(); ++y)
      for (int x = 0; x < c.radiance.width(); ++x) {
        Vec3 v = c.radiance.rgb(x, y);
        ASSERT_TRUE(std::isfinite(v.x + v.y + v.z) && v.x >= 0 && v.y >= 0 && v.z >= 0) << name;
        lum += luminance(v);
      }
    EXPECT_GT(lum, 0) << name;
  }
  // The crypt is "about 500 triangles" (Granier et al.).
  Scene crypt = load_scene("crypt");
  EXPECT_GT(crypt.surfaces[0].mesh.triangle_count(), 400u);
  EXPECT_LT(crypt.surfaces[0].mesh.triangle_count(), 600u);
  // The T-corridor comes with its proxy mesh.
  Scene t = load_scene("t-corridor");
  EXPECT_GT(t.proxy_mesh().triangle_count(), 10u);
}

TEST(LabScene, LowScene2RedSpotLightsAboutHalfTheVolume) {
  // Löw et al., Fig. 8b: "one red spotlight that is blocked to illuminate roughly half of the scene".
  constexpr double kHalfLo = 0.35, kHalfHi = 0.65;  // "roughly half"
  Scene s = load_scene("low-scene2");
  const Emitter* red = nullptr;
  for (const Emitter& e : s.emitters)
    if (e.type == EmitterType::Spot) red = &e;
  ASSERT_NE(red, nullptr);
  int lit = 0, n = 0;
  for (Vec3 p : grid_positions(s.volume_min, s.volume_max, 6, 6, 6)) {
    Vec3 w = red->position - p;
    double d = length(w);
    w = w / d;
    ++n;
    if (red->intensity_towards(-w).x > 0 && !s.tracer().occluded(p, w, 1e-4, d * (1 - 1e-4))) ++lit;
  }
  EXPECT_GT(static_cast<double>(lit) / n, kHalfLo);
  EXPECT_LT(static_cast<double>(lit) / n, kHalfHi);
}

TEST(LabScene, BadFilesNameTheFieldAtFault) {
  fs::path dir = temp_dir("bad");
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    fs::path f = dir / "s.json";
    std::ofstream(f) << text;
    try {
      load_scene(f.string());
      ADD_FAILURE() << "no error for " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error("{", "not valid JSON");
  expect_error(R"({"format":"iblkit.scene/2","surfaces":[]})", "format");
  expect_error(R"({"format":"iblkit.scene/1","surfaces":[{"type":"teapot"}]})", "surfaces[0].type");
  expect_error(R"({"format":"iblkit.scene/1","surfaces":[{"type":"quad","center":[0,0],"normal":[0,1,0],"size":1}]})",
               "center");
  expect_error(
      R"({"format":"iblkit.scene/1","surfaces":[],"emitters":[{"type":"area","center":[0,1,0],"normal":[0,-1,0],"size":1,"radiance":-1}]})",
      "emitters[0].radiance");
  expect_error(R"({"format":"iblkit.scene/1","surfaces":[{"type":"mesh","file":"nope.obj"}]})", "nope.obj");
  expect_error(R"({"format":"iblkit.scene/1","surfaces":[{"type":"room","min":[0,0,0],"max":[1,1,1],"albedo":1.5}]})",
               "albedo");
  EXPECT_THROW(load_scene("no-such-scene"), Error);
  fs::remove_all(dir);
}

TEST(LabScene, TexturedAlbedoUnderAUniformSkyReflectsTheTexture) {
  // Under a constant sky L a Lambertian floor gets E = πL and reflects ρ(uv)·L: the texture itself.
  constexpr double kTexTol = 1e-5;  // float texture, texel centres hit exactly by nearest UVs
  fs::path dir = temp_dir("tex");
  Image tex(2, 2, 3);
  tex.set_rgb(0, 0, {0.1, 0.2, 0.3});  // top-left: v near 1
  tex.set_rgb(1, 0, {0.9, 0.8, 0.7});
  tex.set_rgb(0, 1, {0.5, 0.5, 0.5});  // bottom-left: v near 0
  tex.set_rgb(1, 1, {0.2, 0.6, 0.4});
  io::write_image((dir / "t.exr").string(), tex);
  std::ofstream(dir / "s.json") << R"({"format": "iblkit.scene/1",
    "surfaces": [{"type": "quad", "center": [0, 0, 0], "normal": [0, 1, 0], "up": [0, 0, -1], "size": [2, 2],
                  "albedo": {"texture": "t.exr"}}],
    "emitters": [{"type": "environment", "radiance": 1}]})";
  Scene s = load_scene((dir / "s.json").string());
  // u runs along +x, v along `up` (−z): the texel (0,1) (bottom-left) lies at x < 0, z > 0.
  Rng rng(1);
  auto at = [&](double x, double z) { return radiance(s, {x, 1, z}, {0, -1, 0}, rng, s.render); };
  Vec3 bl = at(-0.5, 0.5), tr = at(0.5, -0.5);
  EXPECT_NEAR(bl.x, 0.5, kTexTol);
  EXPECT_NEAR(tr.x, 0.9, kTexTol);
  EXPECT_NEAR(tr.z, 0.7, kTexTol);
  // The same floor as geometry for renderers outside the lab: its mesh and the texture as albedo.
  const auto ds = diffuse_surfaces(s);
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_EQ(ds[0].mesh.triangle_count(), s.surfaces[0].mesh.triangle_count());
  EXPECT_NEAR(ds[0].albedo({0.25, 0.25}).x, 0.5, kTexTol);  // bottom-left texel
  EXPECT_NEAR(ds[0].albedo({0.75, 0.75}).z, 0.7, kTexTol);  // top-right texel
  fs::remove_all(dir);
}

TEST(LabSequence, PositionsFollowGridPathAndVolume) {
  auto g = grid_positions({0, 0, 0}, {1, 2, 3}, 2, 3, 1);
  ASSERT_EQ(g.size(), 6u);
  EXPECT_EQ(g[1].x, 1);
  EXPECT_EQ(g[2].y, 1);
  EXPECT_EQ(g[0].z, 1.5);  // one point along z sits in the middle
  auto p = path_positions({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, 5);
  ASSERT_EQ(p.size(), 5u);
  EXPECT_NEAR(p[2].x, 1, 1e-12);
  EXPECT_NEAR(p[3].y, 0.5, 1e-12);
  auto r = random_positions({-1, 0, 2}, {1, 1, 3}, 100, 9);
  for (Vec3 v : r) EXPECT_TRUE(v.x >= -1 && v.x <= 1 && v.y >= 0 && v.y <= 1 && v.z >= 2 && v.z <= 3);
  EXPECT_EQ(random_positions({-1, 0, 2}, {1, 1, 3}, 100, 9)[42].z, r[42].z);
}

TEST(LabSequence, ClusterPositionsAreGaussianClustersAndPrefixStable) {
  const Vec3 lo{-2, 0, 1}, hi{2, 4, 5};
  const double sigma = 0.05;
  const int k = 8, n = 8000;
  auto p = cluster_positions(lo, hi, k, n, sigma, 3);
  ASSERT_EQ(p.size(), size_t(n));
  for (Vec3 v : p) EXPECT_TRUE(v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y && v.z >= lo.z && v.z <= hi.z);
  // The first 100 of 8000 are the 100-point capture (the study's prefix trick); another seed moves them.
  auto q = cluster_positions(lo, hi, k, 100, sigma, 3);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(p[size_t(i)].x, q[size_t(i)].x);
  EXPECT_NE(cluster_positions(lo, hi, k, 100, sigma, 4)[0].x, q[0].x);
  // Point i belongs to cluster i mod k. A cluster whose mean lies ≥ 5σ inside every face is an
  // untruncated isotropic Gaussian: mean squared distance to its mean 3σ² (1000 points: ±9 % at 2σ).
  int checked = 0;
  for (int c = 0; c < k; ++c) {
    Vec3 m{0, 0, 0};
    for (int i = c; i < n; i += k) m = m + p[size_t(i)] * (1.0 / (n / k));
    bool inner = true;
    for (int a = 0; a < 3; ++a) inner = inner && m[a] - lo[a] > 5 * sigma && hi[a] - m[a] > 5 * sigma;
    if (!inner) continue;
    double s2 = 0;
    for (int i = c; i < n; i += k) s2 += dot(p[size_t(i)] - m, p[size_t(i)] - m) / (n / k);
    EXPECT_NEAR(s2 / (3 * sigma * sigma), 1.0, 0.09) << "cluster " << c;
    ++checked;
  }
  EXPECT_GE(checked, 4);
  EXPECT_THROW(cluster_positions(lo, hi, 0, 10, sigma, 1), Error);
  EXPECT_THROW(cluster_positions(lo, hi, 11, 10, sigma, 1), Error);
  EXPECT_THROW(cluster_positions(lo, hi, 2, 10, 0, 1), Error);
  EXPECT_THROW(cluster_positions(lo, hi, 2, 10, std::nan(""), 1), Error);
  EXPECT_THROW(cluster_positions({std::nan(""), 0, 0}, hi, 2, 10, sigma, 1), Error);
  EXPECT_THROW(cluster_positions(lo, hi, 2, 1000000000, sigma, 1), Error);
}

TEST(LabSequence, ManifestsListEveryFrameAndTheProxy) {
  Scene s = load_scene("low-scene1");
  fs::path dir = temp_dir("seq");
  SequenceDesc d;
  d.capture.mapping = sphere::MappingKind::MirrorBall;
  d.capture.camera = Camera::MirrorBall;
  d.capture.size = 24;
  d.out_dir = (dir / "seq").string();
  auto pos = grid_positions(s.volume_min, s.volume_max, 2, 1, 2);
  SequenceResult r = write_sequence(s, pos, d);
  auto m = nlohmann::json::parse(std::ifstream(r.manifest));
  EXPECT_EQ(m["format"], "iblkit.sequence/1");
  EXPECT_EQ(m["mapping"], "mirrorball");
  ASSERT_EQ(m["probes"].size(), 4u);
  for (auto& p : m["probes"]) EXPECT_TRUE(fs::exists(fs::path(d.out_dir) / p["image"].get<std::string>()));
  EXPECT_EQ(m["probes"][3]["position"][2].get<double>(), s.volume_max.z);
  EXPECT_TRUE(fs::exists(r.contact_sheet));

  d.capture = CaptureDesc{};
  d.capture.size = 16;
  d.out_dir = (dir / "fusion").string();
  SequenceResult f = write_probe_set(s, {{0, 1, 0}, {0.3, 1.2, 0.1}}, d);
  auto pm = nlohmann::json::parse(std::ifstream(f.manifest));
  EXPECT_EQ(pm["format"], "iblkit.probes/1");
  EXPECT_TRUE(fs::exists(fs::path(d.out_dir) / pm["proxy"].get<std::string>()));
  for (auto& p : pm["probes"]) EXPECT_TRUE(fs::exists(fs::path(d.out_dir) / p["depth"].get<std::string>()));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ibl::lab
