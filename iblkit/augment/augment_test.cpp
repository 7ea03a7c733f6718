// augment/ against closed forms on a tiny scene: a 4 m floor seen from straight above (64×48 pixels),
// lit by a constant sky (the white furnace: E = π L on the floor, L_obj = ρ L on an object) or a sun.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

#include "iblkit/augment/composite.h"
#include "iblkit/augment/light.h"
#include "iblkit/augment/match.h"
#include "iblkit/augment/measure.h"
#include "iblkit/augment/overlay.h"
#include "iblkit/augment/testing.h"
#include "iblkit/core/error.h"
#include "iblkit/render/objects.h"

namespace ibl::augment {
namespace {

constexpr int kW = 64, kH = 48;
constexpr double kFloorAlbedo = 0.5;

geometry::Camera top_camera() {
  geometry::Camera c;
  c.eye = {0, 3, 0};
  c.target = {0, 0, 0};
  c.up = {0, 0, -1};  // image up is −Z, image right is +X
  c.fov_y_deg = 60;
  c.width = kW;
  c.height = kH;
  return c;
}

// The pixel that sees floor point (x, 0, z) from top_camera().
std::pair<int, int> pixel_of(double x, double z) {
  geometry::Camera c = top_camera();
  double t = std::tan(c.fov_y_deg * kPi / 360.0), aspect = static_cast<double>(kW) / kH;
  double px = (x / 3 / (t * aspect) + 1) * kW / 2, py = (1 - (-z / 3) / t) * kH / 2;
  return {static_cast<int>(px), static_cast<int>(py)};
}

geometry::TriMesh floor_mesh() { return geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 6, 6); }

LocalRadiance constant_sky(Vec3 L, Vec3 centre) {
  LocalRadiance l;
  Image img(64, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) img.set_rgb(x, y, L);
  l.map = sphere::EnvMap(img, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  l.centre = centre;
  l.source = "test sky";
  return l;
}

Image constant_photo(double v) { return testing::constant_photo(kW, kH, v); }
using testing::sphere_at;

TEST(AugmentComposite, WhiteFurnaceFloorGivesItsAlbedoAndAHiddenObjectChangesNothing) {
  // Photo: ρ L on a floor under a constant sky L = 1. The object sits below the floor: no ray meets it.
  Image photo = constant_photo(kFloorAlbedo);
  auto r = composite(photo, top_camera(), floor_mesh(), constant_sky({1, 1, 1}, {0, 0.5, 0}),
                     sphere_at({0, -1, 0}, 0.4), {0.7, 0.7, 0.7});
  constexpr double kMeanAlbedoTol = 0.01;  // 64 stratified patch samples per pixel, averaged over 3072 pixels
  double sum = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      sum += r.albedo.rgb(x, y).y;
      ASSERT_EQ(r.composite.rgb(x, y).y, photo.rgb(x, y).y);  // exactly the photograph
      ASSERT_EQ(r.difference.rgb(x, y).y, 0.0);
      ASSERT_NEAR(r.render_without.rgb(x, y).y, photo.rgb(x, y).y, 1e-6);
    }
  EXPECT_NEAR(sum / (kW * kH), kFloorAlbedo, kMeanAlbedoTol);
  EXPECT_EQ(r.stats.changed_pixels, 0);
  EXPECT_EQ(r.stats.object_pixels, 0);
  EXPECT_EQ(r.stats.proxy_pixels, kW * kH);
}

TEST(AugmentComposite, DifferenceIsExactlyZeroWhereAWallHidesTheObject) {
  geometry::TriMesh proxy = floor_mesh();
  proxy.append(geometry::make_quad({0.3, 1.5, 0}, {-1, 0, 0}, {0, 1, 0}, 6, 3));  // a wall at x = 0.3
  Image photo = constant_photo(kFloorAlbedo);
  geometry::Camera cam = top_camera();  // above the far side of the wall, so that it sees the floor there
  cam.eye.x = cam.target.x = 1.2;
  auto r = composite(photo, cam, proxy, constant_sky({1, 1, 1}, {-0.5, 0.5, 0}), sphere_at({-0.5, 0.25, 0}, 0.4),
                     {0.7, 0.7, 0.7});
  int changed_left = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      Vec3 d = cam.pixel_direction(x, y);
      double fx = cam.eye.x + 3 * d.x / -d.y;  // floor x seen at the pixel (or behind the wall)
      if (fx > 0.35) {
        ASSERT_EQ(r.difference.rgb(x, y).y, 0.0) << x << "," << y;
      }
      if (fx < 0.3 && r.difference.rgb(x, y).y != 0) ++changed_left;
    }
  EXPECT_EQ(changed_left, 0);  // the wall's back, seen from this side, does not see the object either
  auto r2 = composite(photo, top_camera(), proxy, constant_sky({1, 1, 1}, {-0.5, 0.5, 0}),
                      sphere_at({-0.5, 0.25, 0}, 0.4), {0.7, 0.7, 0.7});
  EXPECT_GT(r2.stats.changed_pixels, 0);  // from above the object: its floor and the wall's front do change
}

TEST(AugmentLight, AFloorsTableLeavesOutWhatItCannotSeeAndStaysUnbiased) {
  // A sky (1 above, a bright band low in the west) over the floor: the map's lower half sees the floor
  // (radiance 0.5). A floor point's table must leave out the floor's own patches and the sky below its
  // horizon, and its estimate of E must have the exact sum over the patches as its expectation, with less
  // spread than the plain table's (which spends a quarter of its samples on the floor). The guided search
  // must find the patch a search of the whole CDF finds.
  LocalRadiance l;
  Image img(64, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) img.set_rgb(x, y, y < 16 ? Vec3{1, 1, 1} : Vec3{0.5, 0.5, 0.5});
  for (int x = 0; x < 8; ++x) img.set_rgb(x, 13, {40, 40, 40});
  l.map = sphere::EnvMap(img, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  l.centre = {0, 0.5, 0};
  const geometry::TriMesh floor = floor_mesh();
  geometry::RayTracer rt;
  rt.add(floor);
  rt.commit();
  LightField field(l, floor, rt);
  const Vec3 up{0, 1, 0}, x{0.3, 1e-4, -0.2};
  const int table = field.table_for(up);
  ASSERT_GE(table, 0);
  EXPECT_EQ(field.tables(), 2u);  // the floor's two sides
  EXPECT_GE(field.table_for(-up), 0);
  EXPECT_NE(field.table_for(-up), table);
  EXPECT_EQ(field.table_for(normalize(Vec3{0, 1, 0.5})), -1);  // 27° off: the plain table
  double exact = 0, total = 0, floor_share = 0;
  for (size_t i = 0; i < field.size(); ++i) {
    Vec3 w;
    double dist;
    exact += field.contribution(i, x, up, &w, &dist).y;
    total += field.pmf(i, table);
    if (field.local(i)) floor_share += field.pmf(i, table);
  }
  EXPECT_NEAR(total, 1.0, 1e-9);
  std::vector<double> cdf;  // the conditioned table's CDF, rebuilt from its probabilities
  for (size_t i = 0; i < field.size(); ++i) cdf.push_back((cdf.empty() ? 0.0 : cdf.back()) + field.pmf(i, table));
  for (int k = 0; k < 20000; ++k) {
    const double u = (k + 0.5) / 20000;
    double pmf;
    const size_t want = std::min<size_t>(
        field.size() - 1, static_cast<size_t>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()));
    ASSERT_EQ(field.sample(u, &pmf, table), want) << "u = " << u;
  }
  constexpr double kPlainShare = 0.3;   // the plain table's share of a conditioned one
  EXPECT_LE(floor_share, kPlainShare);  // the floor's patches are what the plain part gives them
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> uni(0, 1);
  auto spread = [&](int t, double* mean) {
    constexpr int kTrials = 4000, kSamples = 16;
    double s1 = 0, s2 = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
      double e = 0;
      for (int k = 0; k < kSamples; ++k) {
        double pmf;
        size_t i = field.sample((k + uni(gen)) / kSamples, &pmf, t);
        Vec3 w;
        double dist;
        e += field.contribution(i, x, up, &w, &dist).y / pmf;
      }
      e /= kSamples;
      s1 += e;
      s2 += e * e;
    }
    *mean = s1 / kTrials;
    return std::sqrt(std::max(0.0, s2 / kTrials - *mean * *mean) / kTrials);  // the mean's standard error
  };
  double mean_table, mean_plain;
  const double se_table = spread(table, &mean_table), se_plain = spread(-1, &mean_plain);
  EXPECT_NEAR(mean_table, exact, 4 * se_table);
  EXPECT_NEAR(mean_plain, exact, 4 * se_plain);
  EXPECT_LT(
      se_table,
      0.9 * se_plain);  // 0.87 measured: stratified, the plain table spends its floor samples in strata of their own
}

TEST(AugmentComposite, SunCastsAFullShadowAndLeavesTheSunlitFloorAlone) {
  LocalRadiance sun;
  Image img(64, 32, 3);
  img.set_rgb(20, 8, {5000, 5000, 5000});  // one texel ≈ 48° from the zenith
  sun.map = sphere::EnvMap(img, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  sun.centre = {0, 0.5, 0};
  Vec3 d;
  sun.map.mapping.to_direction(20.5, 8.5, &d);
  const Vec3 c{0, 0.5, 0};
  Vec3 umbra = c - d * (c.y / d.y);
  CompositeDesc desc;
  desc.bounce_samples = 0;
  Image photo = constant_photo(kFloorAlbedo);
  auto r = composite(photo, top_camera(), floor_mesh(), sun, sphere_at(c, 0.4), {0.7, 0.7, 0.7}, desc);
  auto [ux, uy] = pixel_of(umbra.x, umbra.z);
  ASSERT_EQ(r.mask.at(ux, uy, 0), 0.0f);  // the shadow is not hidden behind the object
  constexpr double kUmbraTol = 1e-9;      // every sample is the sun's texel, blocked
  EXPECT_NEAR(r.composite.rgb(ux, uy).y, 0.0, kUmbraTol);
  auto [fx, fy] = pixel_of(-1.5, 1.2);  // far from the shadow, in the sun
  EXPECT_EQ(r.composite.rgb(fx, fy).y, photo.rgb(fx, fy).y);
}

TEST(AugmentComposite, ObjectUnderTheWhiteFurnaceHasRadianceAlbedoTimesL) {
  constexpr double kL = 2.0, kRho = 0.6;
  Image photo = constant_photo(kFloorAlbedo * kL);
  auto r = composite(photo, top_camera(), floor_mesh(), constant_sky({kL, kL, kL}, {0, 0.5, 0}),
                     sphere_at({0, 0.5, 0}, 0.6), {kRho, kRho, kRho});
  double sum = 0;
  int n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (r.mask.at(x, y, 0) >= 1) {
        sum += r.composite.rgb(x, y).y;
        ++n;
      }
  ASSERT_GT(n, 50);
  constexpr double kObjectTol = 0.02;  // 256 samples per pixel; the floor patches are flat 1/0.05-clamped texels
  EXPECT_NEAR(sum / n, kRho * kL, kObjectTol * kRho * kL);
  EXPECT_GT(r.stats.changed_pixels, 0);  // it shadows and lights the floor around it
}

// Mean radiance (green) over the pixels the object covers wholly, and their count.
std::pair<double, int> object_mean(const CompositeResult& r, int channel = 1) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (r.mask.at(x, y, 0) >= 1) {
        sum += r.composite.rgb(x, y)[channel];
        ++n;
      }
  return {n > 0 ? sum / n : 0, n};
}

TEST(AugmentComposite, TextureMultipliesTheAlbedoAtTheObjectsUVs) {
  constexpr double kL = 2.0;
  Image photo = constant_photo(kFloorAlbedo * kL);
  auto sky = constant_sky({kL, kL, kL}, {0, 0.5, 0});
  // A constant texture: each channel's radiance is its texel times ρL.
  render::Material m{{0.8, 0.8, 0.8}, {0, 0, 0}};
  Image tex(4, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) tex.set_rgb(x, y, {0.25, 0.5, 1.0});
  m.texture = std::make_shared<Image>(tex);
  auto r = composite(photo, top_camera(), floor_mesh(), sky, sphere_at({0, 0.5, 0}, 0.6), m);
  constexpr double kObjectTol = 0.02;  // as the white furnace above
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(object_mean(r, c).first, 0.8 * tex.rgb(0, 0)[c] * kL, kObjectTol * 0.8 * kL) << c;
  // Half black, half white around the sphere (u from +X): the sphere's −Z and +Z sides (u = ¼ and ¾,
  // the two texel columns' centres) are black and white.
  Image half(2, 1, 3);
  half.set_rgb(1, 0, {1, 1, 1});
  m.texture = std::make_shared<Image>(half);
  r = composite(photo, top_camera(), floor_mesh(), sky, sphere_at({0, 0.5, 0}, 0.6), m);
  auto [ax, ay] = pixel_of(0, 0.2);
  auto [bx, by] = pixel_of(0, -0.2);
  double a = r.composite.rgb(ax, ay).y, b = r.composite.rgb(bx, by).y;
  ASSERT_EQ(r.mask.at(ax, ay, 0), 1.0f);
  ASSERT_EQ(r.mask.at(bx, by, 0), 1.0f);
  constexpr double kHalfTol = 0.1;  // the pixels are not exactly on the texel centres; the sphere is curved there
  EXPECT_NEAR(std::min(a, b), 0.0, kHalfTol * 0.8 * kL) << a << " " << b;
  EXPECT_NEAR(std::max(a, b), 0.8 * kL, 0.25 * 0.8 * kL) << a << " " << b;
}

TEST(AugmentComposite, GlossyLobeUnderTheWhiteFurnaceReflectsItsWeightTimesL) {
  // The normalised Phong lobe (s+1)/2π (r·l)^s integrates to 1 over the hemisphere when r = n (the sphere's
  // top, seen from straight above): a glossy object of weight k and no diffuse part has radiance k L there.
  constexpr double kL = 2.0, kGloss = 0.5;
  Image photo = constant_photo(kFloorAlbedo * kL);
  render::Material m{{0, 0, 0}, {kGloss, kGloss, kGloss}, 8.0};
  CompositeDesc d;
  d.object_samples = 4096;
  auto r = composite(photo, top_camera(), floor_mesh(), constant_sky({kL, kL, kL}, {0, 0.5, 0}),
                     sphere_at({0, 0.5, 0}, 0.6), m, d);
  // Pixels within 0.1 m of the sphere's top (normals within 20° of the view: the lobe stays in the hemisphere).
  double sum = 0;
  int n = 0;
  for (double x = -0.1; x <= 0.1; x += 0.05)
    for (double z = -0.1; z <= 0.1; z += 0.05) {
      auto [px, py] = pixel_of(x, z);
      sum += r.composite.rgb(px, py).y;
      ++n;
    }
  constexpr double kGlossTol = 0.06;  // power sampling of a constant sky puts few samples into an exponent-8 lobe
  EXPECT_NEAR(sum / n, kGloss * kL, kGlossTol * kGloss * kL);
  // A Lambertian object of the same weight is as bright at the top: the lobe neither gains nor loses light.
  auto lam = composite(photo, top_camera(), floor_mesh(), constant_sky({kL, kL, kL}, {0, 0.5, 0}),
                       sphere_at({0, 0.5, 0}, 0.6), Vec3{kGloss, kGloss, kGloss}, d);
  EXPECT_NEAR(object_mean(lam).first, kGloss * kL, kGlossTol * kGloss * kL);
}

TEST(AugmentComposite, WhiteObjectInTheWhiteFurnaceSendsBackWhatItBlocks) {
  // Everything white under a constant sky: the object's light on the floor (one bounce object → proxy) makes up
  // for the light it blocks, up to the second bounce the reference leaves out (the floor under it, darkened,
  // lights its underside less). Without the bounce the floor under it is much darker.
  constexpr double kL = 1.0;
  Image photo = constant_photo(kL);  // a white floor: ρ = 1
  auto sky = constant_sky({kL, kL, kL}, {0, 0.6, 0});
  CompositeDesc d;
  d.light_samples = 256;
  d.bounce_samples = 64;
  const geometry::TriMesh obj = sphere_at({0, 0.5, 0}, 0.6);
  auto with = composite(photo, top_camera(), floor_mesh(), sky, obj, Vec3{1, 1, 1}, d);
  d.bounce_samples = 0;
  auto without = composite(photo, top_camera(), floor_mesh(), sky, obj, Vec3{1, 1, 1}, d);
  // Floor pixels in a ring 0.35..0.5 m from the sphere's axis (just outside it as seen from above).
  double dw = 0, dn = 0;
  int n = 0;
  for (int k = 0; k < 16; ++k) {
    double a = 2 * kPi * k / 16;
    auto [px, py] = pixel_of(0.42 * std::cos(a), 0.42 * std::sin(a));
    if (with.mask.at(px, py, 0) > 0) continue;
    dw += with.difference.rgb(px, py).y;
    dn += without.difference.rgb(px, py).y;
    ++n;
  }
  ASSERT_GT(n, 8);
  dw /= n;
  dn /= n;
  EXPECT_LT(dn, -0.1 * kL);                     // the shadow alone: more than a tenth of the light gone
  EXPECT_LT(std::abs(dw), 0.3 * std::abs(dn));  // the bounce gives most of it back
}

// The inside of a hemispherical bowl of radius r centred at c, opening up (+Y), its triangles facing its centre.
geometry::TriMesh bowl(Vec3 c, double r, int rings = 24, int segments = 48) {
  geometry::TriMesh m;
  for (int i = 0; i <= rings; ++i) {
    const double theta = 0.5 * kPi * i / rings;  // 0 at the bottom, π/2 at the rim
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      m.positions.push_back(
          c + Vec3{r * std::sin(theta) * std::cos(phi), -r * std::cos(theta), r * std::sin(theta) * std::sin(phi)});
    }
  }
  auto at = [&](int i, int j) { return static_cast<uint32_t>(i * segments + (j % segments)); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      std::array<uint32_t, 3> t1{at(i, j), at(i + 1, j), at(i + 1, j + 1)},
          t2{at(i, j), at(i + 1, j + 1), at(i, j + 1)};
      for (auto t : {t1, t2}) {
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
        m.triangles.push_back(t);
        const size_t k = m.triangles.size() - 1;
        const Vec3 centroid = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0;
        if (dot(m.normal(k), c - centroid) < 0) std::swap(m.triangles[k][1], m.triangles[k][2]);
      }
    }
  return m;
}

TEST(AugmentComposite, TheObjectLightsItselfOnceInABowl) {
  // Closed form: every point inside a spherical surface sees any part of it with a view factor proportional to that
  // part's area, so from any point of a hemispherical bowl half the cosine-weighted hemisphere leaves through the
  // opening (to a constant sky L) and half meets the bowl. Its direct radiance is ρL/2 everywhere; one bounce of it
  // on itself adds ρ·(ρL/2)/2: L_bowl = ρL/2 + ρ²L/4 (0.39 L against 0.30 L for ρ = 0.6).
  constexpr double kL = 1.0, kRho = 0.6;
  Image photo = constant_photo(kFloorAlbedo);
  auto sky = constant_sky({kL, kL, kL}, {0, 1.2, 0});
  CompositeDesc d;
  d.object_samples = 2048;
  d.triangle_samples = 256;
  const geometry::TriMesh obj = bowl({0, 0.9, 0}, 0.6);
  const auto with = composite(photo, top_camera(), floor_mesh(), sky, obj, Vec3{kRho, kRho, kRho}, d);
  d.self_light = false;
  const auto without = composite(photo, top_camera(), floor_mesh(), sky, obj, Vec3{kRho, kRho, kRho}, d);
  // Pixels seeing the bowl's inside within 0.4 m of its axis (seen from above: away from the rim).
  double w = 0, wo = 0;
  int n = 0;
  for (int k = 0; k < 25; ++k) {
    auto [px, py] = pixel_of(0.08 * (k % 5 - 2) * 2, 0.08 * (k / 5 - 2) * 2);
    if (with.mask.at(px, py, 0) < 1) continue;
    w += with.composite.rgb(px, py).y;
    wo += without.composite.rgb(px, py).y;
    ++n;
  }
  ASSERT_GT(n, 15);
  w /= n;
  wo /= n;
  std::printf("bowl: %.4f without its own light (closed form %.4f), %.4f with (%.4f)\n", wo, kRho * kL / 2, w,
              kRho * kL / 2 + kRho * kRho * kL / 4);
  EXPECT_NEAR(wo, kRho * kL / 2, 0.04 * kRho * kL / 2) << "direct light inside the bowl";
  EXPECT_NEAR(w, kRho * kL / 2 + kRho * kRho * kL / 4, 0.04 * (kRho * kL / 2 + kRho * kRho * kL / 4))
      << "with the bowl's light on itself";
}

TEST(AugmentComposite, BadInputFailsWithAClearMessage) {
  Image photo = constant_photo(kFloorAlbedo);
  auto sky = constant_sky({1, 1, 1}, {0, 0.5, 0});
  geometry::Camera cam = top_camera();
  cam.width = 32;
  try {
    composite(photo, cam, floor_mesh(), sky, sphere_at({0, 0.5, 0}, 0.4), {0.5, 0.5, 0.5});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the photograph is 64x48 but the camera's frame is 32x48"), std::string::npos)
        << e.what();
  }
  try {
    composite(photo, top_camera(), floor_mesh(), sky, sphere_at({0, 0.1, 0}, 0.4), {0.5, 0.5, 0.5});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the object intersects the proxy"), std::string::npos) << e.what();
  }
  try {  // the camera inside a closed box whose faces point outwards
    composite(photo, top_camera(), geometry::make_box({-4, -1, -4}, {4, 5, 4}), sky, sphere_at({0, 0.5, 0}, 0.4),
              {0.5, 0.5, 0.5});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is inside the proxy"), std::string::npos) << e.what();
  }
}

TEST(AugmentComposite, AnObjectRestingOnTheFloorIsAccepted) {
  // The most common placement: a sphere whose lowest vertex lies on the floor, and a blob moved so that
  // its lowest point does. Touching is not intersecting; sinking 1 cm into the floor is.
  Image photo = constant_photo(kFloorAlbedo);
  auto sky = constant_sky({1, 1, 1}, {0, 0.5, 0});
  CompositeDesc d;
  d.light_samples = d.object_samples = 4;
  d.bounce_samples = 0;
  EXPECT_NO_THROW(composite(photo, top_camera(), floor_mesh(), sky, sphere_at({0, 0.2, 0}, 0.4), {0.5, 0.5, 0.5}, d));
  geometry::TriMesh blob = render::make_object({"blob", 0.3, 2000, {0, 0, 0}});
  Vec3 lo, hi;
  blob.bounds(&lo, &hi);
  blob.transform(1.0, {0, -lo.y, 0});
  EXPECT_NO_THROW(composite(photo, top_camera(), floor_mesh(), sky, blob, {0.5, 0.5, 0.5}, d));
  blob.transform(1.0, {0, -0.01, 0});
  EXPECT_THROW(composite(photo, top_camera(), floor_mesh(), sky, blob, {0.5, 0.5, 0.5}, d), Error);
}

TEST(AugmentMatch, TheGainsAreWhatThePhotographAndTheProbeSeeOfTheSameFloor) {
  // A probe 0.5 m above a floor sees it as 0.25 (its lower hemisphere) under a sky of 1; the photograph,
  // another exposure and white balance, shows the floor as (0.5, 0.45, 0.3): the gains are their ratio.
  LocalRadiance probe = constant_sky({1, 1, 1}, {0, 0.5, 0});
  for (int y = 16; y < 32; ++y)
    for (int x = 0; x < 64; ++x) probe.map.image.set_rgb(x, y, {0.25, 0.25, 0.25});
  Image photo(kW, kH, 3);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) photo.set_rgb(x, y, {0.5, 0.45, 0.3});
  const MatchResult m = estimate_match(photo, top_camera(), floor_mesh(), probe);
  ASSERT_TRUE(m.valid);
  EXPECT_EQ(m.points, kW * kH);
  EXPECT_NEAR(m.gain.x, 2.0, 1e-6);
  EXPECT_NEAR(m.gain.y, 1.8, 1e-6);
  EXPECT_NEAR(m.gain.z, 1.2, 1e-6);
  EXPECT_NEAR(m.spread, 0, 1e-9);
  const PixelRect card{10, 12, 8, 5};  // a grey card: its pixels alone
  const MatchResult mc = estimate_match(photo, top_camera(), floor_mesh(), probe, 0, 40000, &card);
  ASSERT_TRUE(mc.valid);
  EXPECT_EQ(mc.points, 8 * 5);
  EXPECT_NEAR(mc.gain.y, 1.8, 1e-6);
  const PixelRect outside{60, 40, 10, 10};
  EXPECT_THROW(estimate_match(photo, top_camera(), floor_mesh(), probe, 0, 40000, &outside), Error);
  const LocalRadiance matched = scaled(probe, m.gain);
  EXPECT_NEAR(matched.map.image.at(3, 20, 1), 0.45, 1e-6);
  // Saturated pixels are left out, and a probe that sees none of the points gives no gain.
  EXPECT_FALSE(estimate_match(photo, top_camera(), floor_mesh(), probe, 0.2).valid);
  LocalRadiance under = probe;
  under.centre = {0, -0.5, 0};  // below the floor: the floor hides every point from it
  EXPECT_FALSE(estimate_match(photo, top_camera(), floor_mesh(), under).valid);
  EXPECT_THROW(estimate_match(Image(4, 4, 3), top_camera(), floor_mesh(), probe), Error);
}

TEST(AugmentOverlay, TheProxysOutlineIsDrawnWhereTheCameraSeesItAndItsDiagonalsAreNot) {
  // A 6 m floor from 3 m above with a 60° view: its edges fall outside the frame; a 1 m square tile of two
  // triangles in the middle (0.01 m up) shows its outline, not its diagonal; a box in front hides what is behind.
  geometry::TriMesh tile = geometry::make_quad({0, 0.01, 0}, {0, 1, 0}, {0, 0, -1}, 1, 1);
  const Image black(kW, kH, 3);
  const Image o = proxy_overlay(black, top_camera(), tile);
  auto lit = [&](double x, double z) {  // the tile's point (x, z) seen at a green pixel?
    auto [px, py] = pixel_of(x, z);
    double g = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        g = std::max<double>(g, o.at(std::clamp(px + dx, 0, kW - 1), std::clamp(py + dy, 0, kH - 1), 1));
    return g > 0.3;
  };
  EXPECT_TRUE(lit(0.5, 0.0));     // its right edge
  EXPECT_TRUE(lit(0.0, -0.5));    // its far edge
  EXPECT_FALSE(lit(0.2, 0.2));    // on its diagonal (x = z): not a feature edge
  EXPECT_FALSE(lit(0.25, -0.1));  // inside
  EXPECT_THROW(proxy_overlay(Image(3, 3, 3), top_camera(), tile), Error);
  // Through a strong lens, edges far outside the frame project where the polynomial folds back (10⁶ px away):
  // they are not drawn (drawing them once took minutes) and what is in the frame still is.
  geometry::Camera lens = top_camera();
  lens.intrinsics = geometry::Intrinsics{40, 40, kW / 2.0, kH / 2.0};
  lens.distortion = {-0.45, 0.1, 0, 0, 0};
  const Image wide = proxy_overlay(black, lens, geometry::make_box({-50, -1, -50}, {50, 0.01, 50}));
  EXPECT_EQ(wide.width(), kW);
}

TEST(AugmentMeasure, PerfectCompositeHasNoErrorAndShadowErrorIsRelative) {
  Image photo = constant_photo(1.0), truth = constant_photo(1.0), mask(kW, kH, 1);
  for (int x = 0; x < 10; ++x) mask.at(x, 0, 0) = 1;
  for (int x = 0; x < 10; ++x) truth.set_rgb(x, 5, {0.5, 0.5, 0.5});  // a shadow: half as bright
  CompositeErrors e = measure(photo, truth, truth, mask);
  EXPECT_EQ(e.object, 0);
  EXPECT_EQ(e.shadow, 0);
  EXPECT_EQ(e.unchanged, 0);
  EXPECT_GE(e.shadow_pixels, 10);  // the row and, through the 3×3 classification, its neighbours
  EXPECT_GT(e.shadow_signal, 0.1);
  Image pasted = photo;  // no shadow at all: the whole signal is the error
  EXPECT_NEAR(measure(photo, pasted, truth, mask).shadow, 1.0, 1e-12);
}

}  // namespace
}  // namespace ibl::augment
