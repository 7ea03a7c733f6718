#include "iblkit/nearfield/scene_render.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "iblkit/core/error.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/nearfield/ies.h"
#include "iblkit/nearfield/reconstruct.h"
#include "iblkit/nearfield/spotlight.h"

namespace ibl::nearfield {
namespace {

namespace fs = std::filesystem;

// The bike light simulated (9×7 positions, as the docs, at 32² images), written to a temporary folder of
// its own (CTest runs the tests in parallel).
struct Fixture {
  fs::path dir;
  std::string manifest;
  explicit Fixture(const std::string& name)
      : dir(fs::temp_directory_path() / ("iblkit_scene_render_" + name)), manifest((dir / "bike.json").string()) {
    fs::create_directories(dir);
    SimulateDesc sd;
    sd.nx = 9;
    sd.ny = 7;
    sd.resolution = 32;
    write_dataset(manifest, simulate(make_luminaire("bikelight"), sd));
  }
  ~Fixture() { fs::remove_all(dir); }
};

const lab::Scene& crypt() {
  static const lab::Scene s = lab::load_scene("crypt");
  return s;
}

SceneRenderDesc crypt_view(const std::string& dataset) {
  SceneRenderDesc d;
  d.dataset = dataset;
  d.placement.position = {-0.55, 0.45, -0.75};
  d.placement.forward = Vec3{-1.3, 0.25, -1.6} - d.placement.position;
  d.camera.eye = {0.9, 1.5, 0.9};
  d.camera.target = {-1.1, 0.3, -1.5};
  d.camera.fov_y_deg = 55;
  d.camera.width = d.camera.height = 20;
  return d;
}

void expect_same(const Image& a, const Image& b) {
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const Vec3 p = a.rgb(x, y), q = b.rgb(x, y);
      EXPECT_EQ(p.x, q.x);
      EXPECT_EQ(p.y, q.y);
      EXPECT_EQ(p.z, q.z);
    }
}

TEST(NearfieldSceneRender, SpotlightsExactAndFarFieldAsTheirPrimitivesMakeThem) {
  Fixture f("primitives");
  const SceneView sv(lab::diffuse_surfaces(crypt()), crypt().name);
  SceneRenderDesc d = crypt_view(f.manifest);
  d.exact = "auto";
  d.srgbe = true;
  const SceneRender r = render_scene(sv, d);
  const Dataset ds = read_dataset(f.manifest);
  const auto lum = make_luminaire("bikelight");
  EXPECT_EQ(r.label, ds.name);
  EXPECT_EQ(r.spotlights, 63u);
  expect_same(r.near_field, render_spotlights(sv, spotlights(ds, d.placement, true), d.camera, true));
  ASSERT_TRUE(r.exact && r.far_field && r.near_field_error && r.far_field_error && r.srgbe_error);
  expect_same(*r.exact, render_exact(sv, lum, d.placement, d.camera, true));
  EXPECT_EQ(r.near_field_error->rel_rms, compare(r.near_field, *r.exact).rel_rms);
  EXPECT_EQ(r.far_field_error->rel_rms, compare(*r.far_field, *r.exact).rel_rms);
  EXPECT_EQ(r.srgbe_passes, 21u);  // 63 spotlights in passes of 3
  EXPECT_EQ(
      r.srgbe_error->rel_rms,
      compare(render_spotlights(sv, spotlights(ds, d.placement, true), d.camera, true, {}, 3), r.near_field).rel_rms);
  // The near field beats the far field in a scene a metre from the lamp.
  EXPECT_LT(r.near_field_error->rel_rms, r.far_field_error->rel_rms);

  // Without a comparison, only the spotlights' picture; without far field, no far-field picture.
  d.exact = "none";
  d.srgbe = false;
  const SceneRender plain = render_scene(sv, d);
  EXPECT_FALSE(plain.exact || plain.far_field || plain.near_field_error || plain.srgbe_error);
  d.exact = "bikelight";
  d.far_field = false;
  const SceneRender no_far = render_scene(sv, d);
  EXPECT_TRUE(no_far.exact && no_far.near_field_error);
  EXPECT_FALSE(no_far.far_field || no_far.far_field_error);
}

TEST(NearfieldSceneRender, IesFileAndBadParameters) {
  Fixture f("ies");
  const SceneView sv(lab::diffuse_surfaces(crypt()), crypt().name);
  // A cosine lobe (I = 100 cos γ), as in NearfieldIes.
  std::string text = "IESNA:LM-63-2002\n[TEST] cosine\nTILT=NONE\n1 -1 1 19 1 1 2 0 0 0\n1 1 10\n";
  for (int k = 0; k <= 18; ++k) text += std::to_string(k * 10) + " ";
  text += "\n0\n";
  for (int k = 0; k <= 18; ++k) text += std::to_string(k * 10 <= 90 ? 100 * std::cos(k * 10 * kPi / 180) : 0.0) + " ";
  const std::string ies = (f.dir / "cos.ies").string();
  std::ofstream(ies) << text << "\n";
  SceneRenderDesc d = crypt_view("");
  d.ies = ies;
  d.exact = "auto";  // ignored with an IES file
  const SceneRender r = render_scene(sv, d);
  EXPECT_EQ(r.label, ies);
  EXPECT_EQ(r.spotlights, 1u);
  EXPECT_FALSE(r.exact);
  expect_same(r.near_field,
              render_spotlights(sv, {ies_spotlight(read_ies(ies), d.placement, 80, 256)}, d.camera, true));

  d.dataset = f.manifest;  // both
  EXPECT_THROW(render_scene(sv, d), Error);
  d.dataset = d.ies = "";  // neither
  EXPECT_THROW(render_scene(sv, d), Error);
  Dataset measured = read_dataset(f.manifest);
  measured.luminaire.clear();
  EXPECT_THROW(exact_luminaire(measured, "auto"), Error);
  EXPECT_FALSE(exact_luminaire(measured, "none"));
  EXPECT_FALSE(exact_luminaire(measured, ""));
  EXPECT_EQ(exact_luminaire(measured, "flashlight")->name, "flashlight");
  EXPECT_THROW(exact_luminaire(measured, "no-such-lamp"), Error);
}

TEST(NearfieldSceneRender, SceneViewTakesAnyDiffuseSurfaces) {
  // One floor quad without a lab scene: hit at the frame's centre, albedo from the function.
  geometry::DiffuseSurface floor;
  floor.name = "floor";
  floor.mesh.positions = {{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}};
  floor.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  floor.albedo = [](Vec2) { return Vec3{0.25, 0.5, 0.75}; };
  const SceneView sv({floor}, "floor only");
  geometry::Camera c;
  c.eye = {0, 2, 0.001};
  c.target = {0, 0, 0};
  c.width = c.height = 9;
  Vec3 p, n, a;
  ASSERT_TRUE(sv.primary(c, 4, 4, &p, &n, &a));
  EXPECT_NEAR(p.y, 0, 1e-6);  // Embree's single-precision hit distance
  EXPECT_NEAR(n.y, 1, 1e-12);
  EXPECT_EQ(a.z, 0.75);
  EXPECT_THROW(SceneView({}, "empty"), Error);
  geometry::DiffuseSurface bare = floor;
  bare.albedo = nullptr;
  EXPECT_THROW(SceneView({bare}, "no albedo"), Error);
}

}  // namespace
}  // namespace ibl::nearfield
