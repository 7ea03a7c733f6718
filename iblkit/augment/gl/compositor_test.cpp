// The GL compositor on a tiny scene (a 6 m floor seen from above, 96×72 pixels): pixels the object does not
// touch are the photograph bit for bit, a sun's umbra is where the CPU reference puts it, an object under a
// constant sky has radiance ρL, and a wall hides it; the object's material (texture, glossy lobe) is the
// CPU reference's. Skips where no OpenGL 4.5 context can be made.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "iblkit/augment/gl/compositor.h"
#include "iblkit/augment/soft_visibility.h"
#include "iblkit/augment/testing.h"
#include "iblkit/core/error.h"
#include "iblkit/render/gl/context.h"
#include "iblkit/render/objects.h"

namespace ibl::augment::gl {
namespace {

constexpr int kW = 96, kH = 72;

bool same(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

#define SKIP_WITHOUT_GL()                                                                        \
  do {                                                                                           \
    std::string why;                                                                             \
    if (!render::gl::available(&why)) GTEST_SKIP() << "no OpenGL 4.5 through EGL here: " << why; \
  } while (0)

geometry::Camera top_camera() {
  geometry::Camera c;
  c.eye = {0, 3, 0.5};
  c.target = {0, 0, 0};
  c.fov_y_deg = 60;
  c.width = kW;
  c.height = kH;
  return c;
}

geometry::TriMesh floor_mesh() { return geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 6, 6); }

Image constant_photo(double v) { return testing::constant_photo(kW, kH, v); }
using testing::sphere_at;

LocalRadiance sky(Vec3 L, Vec3 sun, Vec3 centre) {
  Image img(64, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) img.set_rgb(x, y, L);
  if (max_component(sun) > 0) img.set_rgb(20, 8, sun);  // one texel ≈ 48° from the zenith
  LocalRadiance l;
  l.map = sphere::EnvMap(img, sphere::Mapping(sphere::MappingKind::LatLong, 64, 32));
  l.centre = centre;
  l.source = "test sky";
  return l;
}

TEST(AugmentGl, PixelsTheObjectDoesNotTouchAreThePhotographBitForBit) {
  SKIP_WITHOUT_GL();
  const Vec3 at{0.3, 0.3, -0.2};
  Image photo = constant_photo(0.4);
  geometry::Camera cam = top_camera();
  cam.fov_y_deg = 90;
  const geometry::TriMesh floor = geometry::make_quad({0, 0, 0}, {0, 1, 0}, {0, 0, -1}, 12, 12);
  auto r = augment::gl::composite(photo, cam, floor, sky({1, 1, 1}, {3000, 3000, 3000}, at), sphere_at(at, 0.3),
                                  {0.7, 0.7, 0.7});
  int far_pixels = 0, changed_near = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      Vec3 d = cam.pixel_direction(x, y);
      Vec3 p = cam.eye + d * (cam.eye.y / -d.y);  // the floor point the pixel sees
      double far = length(p - Vec3{at.x, 0, at.z});
      if (!same(r.difference.rgb(x, y), Vec3{})) ++changed_near;
      // Beyond the soft term's reach (sin²α cos β = r² h / d³ < 4·10⁻³: d > 1.2 m for r = 0.15, h = 0.3) and
      // off the sun's shadow (towards +z, −x) nothing changes.
      if (far > 1.3 && !(p.z > at.z && p.x < at.x + 0.5)) {
        ++far_pixels;
        ASSERT_TRUE(same(r.composite.rgb(x, y), photo.rgb(x, y))) << x << "," << y;
      }
    }
  EXPECT_GT(far_pixels, 500);
  EXPECT_GT(changed_near, 50);
  EXPECT_GT(r.stats.object_pixels, 8);

  // No shadows (the pasted baseline): only the object's pixels change.
  CompositeDesc none;
  none.shadows = false;
  auto p = augment::gl::composite(photo, cam, floor, sky({1, 1, 1}, {3000, 3000, 3000}, at), sphere_at(at, 0.3),
                                  {0.7, 0.7, 0.7}, none);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (p.mask.at(x, y, 0) == 0) ASSERT_TRUE(same(p.composite.rgb(x, y), photo.rgb(x, y))) << x << "," << y;
}

TEST(AugmentGl, SunUmbraFallsWhereTheCpuReferencePutsIt) {
  SKIP_WITHOUT_GL();
  const Vec3 at{0, 0.35, 0};
  Image photo = constant_photo(0.4);
  LocalRadiance sun = sky({0, 0, 0}, {5000, 5000, 5000}, at);
  geometry::TriMesh object = sphere_at(at, 0.3);
  CompositeDesc cd;
  cd.bounce_samples = 0;
  auto cpu = augment::composite(photo, top_camera(), floor_mesh(), sun, object, {0.7, 0.7, 0.7}, cd);
  auto gl = augment::gl::composite(photo, top_camera(), floor_mesh(), sun, object, {0.7, 0.7, 0.7}, cd);
  // The CPU's umbra (≥ 90 % darker, off the object) against the GL's.
  int both = 0, either = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (cpu.mask.at(x, y, 0) > 0 || gl.mask.at(x, y, 0) > 0) continue;
      bool a = cpu.composite.rgb(x, y).y < 0.04, b = gl.composite.rgb(x, y).y < 0.04;
      both += a && b;
      either += a || b;
    }
  ASSERT_GT(either, 30);
  EXPECT_GT(static_cast<double>(both) / either, 0.85);  // the two umbrae overlap (intersection over union)
}

TEST(AugmentGl, ObjectUnderAConstantSkyHasRadianceRhoL) {
  SKIP_WITHOUT_GL();
  // Nothing but sky: the proxy is a small floor far off to the side, the light is constant everywhere (even
  // below), so E = π L on every object normal and the object's radiance is ρ L exactly.
  geometry::TriMesh proxy = geometry::make_quad({5, -5, 0}, {0, 1, 0}, {0, 0, -1}, 0.5, 0.5);
  geometry::Camera cam = top_camera();
  auto r = augment::gl::composite(constant_photo(0.1), cam, proxy, sky({2, 2, 2}, {}, {0, 0.3, 0}),
                                  sphere_at({0, 0.3, 0}, 0.6), {0.5, 0.5, 0.5});
  int full = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (r.mask.at(x, y, 0) == 1) {
        ++full;
        EXPECT_NEAR(r.composite.rgb(x, y).y, 0.5 * 2, 0.01) << x << "," << y;
      }
  EXPECT_GT(full, 100);
}

TEST(AugmentGl, AWallInFrontHidesTheObjectAndTheFrameMovesWithIt) {
  SKIP_WITHOUT_GL();
  geometry::TriMesh proxy = floor_mesh();
  proxy.append(geometry::make_quad({0, 1.5, 0.2}, {0, 0, 1}, {0, 1, 0}, 6, 3));  // a wall between camera and object
  geometry::Camera cam;
  cam.eye = {0, 1, 3};
  cam.target = {0, 0.3, 0};
  cam.width = kW;
  cam.height = kH;
  const Vec3 at{0, 0.3, -0.5};
  auto r = augment::gl::composite(constant_photo(0.3), cam, proxy, sky({1, 1, 1}, {}, at), sphere_at(at, 0.3),
                                  {0.7, 0.7, 0.7});
  EXPECT_EQ(r.stats.object_pixels, 0);

  // The same scene without the wall, through a Compositor: moving the object moves its pixels.
  render::gl::Context ctx;
  Image albedo(kW, kH, 3, 0.3f);
  SplitLight split = split_light(sky({1, 1, 1}, {}, at), floor_mesh());
  Compositor comp(constant_photo(0.3), cam, floor_mesh(), split, albedo);
  comp.set_object(sphere_at(at, 0.3), {0.7, 0.7, 0.7});
  Image m0, m1;
  comp.draw({});
  comp.read_back(nullptr, &m0, nullptr, nullptr);
  comp.draw({0.5, 0, 0});
  comp.read_back(nullptr, &m1, nullptr, nullptr);
  double cx0 = 0, cx1 = 0, n0 = 0, n1 = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      cx0 += x * m0.at(x, y, 0);
      n0 += m0.at(x, y, 0);
      cx1 += x * m1.at(x, y, 0);
      n1 += m1.at(x, y, 0);
    }
  ASSERT_GT(n0, 20);
  ASSERT_GT(n1, 20);
  EXPECT_GT(cx1 / n1, cx0 / n0 + 5);  // to the right
  EXPECT_THROW(Compositor(constant_photo(0.3), cam, floor_mesh(), split, Image(4, 4, 3)), Error);
}

// Sums of the composite over the pixels both paths cover fully, per channel.
struct ObjectSums {
  Vec3 gl, cpu;
  int pixels = 0;
};
// The test frame's camera from eye towards target.
geometry::Camera frame_camera(Vec3 eye, Vec3 target, double fov_deg) {
  geometry::Camera cam;
  cam.eye = eye;
  cam.target = target;
  cam.fov_y_deg = fov_deg;
  cam.width = kW;
  cam.height = kH;
  return cam;
}

// The CPU composite over the floor with 4096 light samples per object pixel (its object nearly noise-free).
CompositeResult cpu_reference(const Image& photo, const geometry::Camera& cam, const LocalRadiance& light,
                              const geometry::TriMesh& object, const render::Material& m) {
  CompositeDesc cd;
  cd.object_samples = 4096;
  return augment::composite(photo, cam, floor_mesh(), light, object, m, cd);
}

ObjectSums object_sums(const CompositeResult& gl, const CompositeResult& cpu) {
  ObjectSums s;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (gl.mask.at(x, y, 0) == 1 && cpu.mask.at(x, y, 0) == 1) {
        s.gl += gl.composite.rgb(x, y);
        s.cpu += cpu.composite.rgb(x, y);
        ++s.pixels;
      }
  return s;
}

TEST(AugmentGl, GlossyLobeUnderAConstantSkyAddsKLWhereTheViewMeetsTheNormal) {
  SKIP_WITHOUT_GL();
  // Constant sky L = 2 everywhere, proxy far off: the diffuse part is ρL; where the view ray meets the
  // sphere head-on the reflected ray is the normal, the whole lobe lies above the horizon and adds kL.
  geometry::TriMesh proxy = geometry::make_quad({5, -5, 0}, {0, 1, 0}, {0, 0, -1}, 0.5, 0.5);
  geometry::Camera cam;
  cam.eye = {0, 3, 0};
  cam.target = {0, 0, 0};
  cam.up = {0, 0, -1};
  cam.fov_y_deg = 30;
  cam.width = kW;
  cam.height = kH;
  render::Material m{{0.3, 0.3, 0.3}, {0.5, 0.25, 0.1}, 20};
  auto r = augment::gl::composite(constant_photo(0.1), cam, proxy, sky({2, 2, 2}, {}, {0, 0.3, 0}),
                                  sphere_at({0, 0.3, 0}, 0.8), m);
  const Vec3 c = r.composite.rgb(kW / 2, kH / 2);
  ASSERT_EQ(r.mask.at(kW / 2, kH / 2, 0), 1);
  EXPECT_NEAR(c.x, 0.3 * 2 + 0.5 * 2, 0.02);
  EXPECT_NEAR(c.y, 0.3 * 2 + 0.25 * 2, 0.02);
  EXPECT_NEAR(c.z, 0.3 * 2 + 0.1 * 2, 0.02);
  render::Material blinn = m;
  blinn.lobe = render::Lobe::BlinnPhong;
  blinn.exponent = 80;  // environment_exponent 20: the same prefiltered map
  auto b = augment::gl::composite(constant_photo(0.1), cam, proxy, sky({2, 2, 2}, {}, {0, 0.3, 0}),
                                  sphere_at({0, 0.3, 0}, 0.8), blinn);
  EXPECT_NEAR(b.composite.rgb(kW / 2, kH / 2).x, 0.3 * 2 + 0.5 * 2, 0.02);
}

TEST(AugmentGl, TextureAndSunHighlightAgreeWithTheCpuReference) {
  SKIP_WITHOUT_GL();
  // A sun (a hard light) over a dim sky, a glossy textured sphere (its left half in UV red, its right half
  // blue), a floor below: the GL object against the CPU's, summed over the pixels both cover.
  const Vec3 at{0, 0.35, 0};
  Image photo = constant_photo(0.4);
  LocalRadiance light = sky({0.3, 0.3, 0.3}, {3000, 3000, 3000}, at);
  auto tex = std::make_shared<Image>(8, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) tex->set_rgb(x, y, x < 4 ? Vec3{0.9, 0.1, 0.1} : Vec3{0.1, 0.1, 0.9});
  render::Material m{{1, 1, 1}, {0.3, 0.3, 0.3}, 30};
  m.texture = tex;
  geometry::TriMesh object = sphere_at(at, 0.5);
  const geometry::Camera cam = frame_camera({0, 1.4, 1.2}, at, 40);
  auto cpu = cpu_reference(photo, cam, light, object, m);
  auto gl = augment::gl::composite(photo, cam, floor_mesh(), light, object, m);
  ObjectSums s = object_sums(gl, cpu);
  ASSERT_GT(s.pixels, 500);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.gl[c] / s.cpu[c], 1.0, 0.08) << "channel " << c;
  // The texture's halves: red and blue dominate in the same pixels.
  int agree = 0, n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (gl.mask.at(x, y, 0) == 1 && cpu.mask.at(x, y, 0) == 1) {
        Vec3 a = gl.composite.rgb(x, y), b = cpu.composite.rgb(x, y);
        agree += (a.x > a.z) == (b.x > b.z);
        ++n;
      }
  EXPECT_GT(static_cast<double>(agree) / n, 0.95);
  // The highlight: the brightest object pixel of each lies within 3 pixels of the other's.
  auto brightest = [&](const CompositeResult& r) {
    int bx = 0, by = 0;
    double best = -1;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        if (gl.mask.at(x, y, 0) == 1 && cpu.mask.at(x, y, 0) == 1 && r.composite.rgb(x, y).y > best) {
          best = r.composite.rgb(x, y).y;
          bx = x;
          by = y;
        }
    return std::pair<int, int>{bx, by};
  };
  auto [gx, gy] = brightest(gl);
  auto [cx, cy] = brightest(cpu);
  EXPECT_LE(std::abs(gx - cx) + std::abs(gy - cy), 3) << "GL " << gx << "," << gy << " CPU " << cx << "," << cy;
  std::printf("textured glossy sphere, GL / CPU over %d pixels: %.4f %.4f %.4f; highlight GL (%d,%d) CPU (%d,%d)\n",
              s.pixels, s.gl.x / s.cpu.x, s.gl.y / s.cpu.y, s.gl.z / s.cpu.z, gx, gy, cx, cy);
}

TEST(AugmentGl, SoftVisibilityDarkensTheUndersideAsTheCpuReferenceDoes) {
  SKIP_WITHOUT_GL();
  // The blob a little above a floor under a sun and a sky that is constant everywhere (so the floor the
  // object sees carries the sky's radiance too): its underside sees the floor its own shadow darkens, its
  // bumps hide part of the sky. The GL object against the CPU's, whole and by half (pixel rows below the
  // blob's centre face the floor), with the soft light's factor per triangle (its share, and the parallax from
  // the map's centre: from the blob's upper half the 6 m floor's edge sits lower than from the centre, a band
  // of directions the CPU's patches leave dark) and without it.
  const Vec3 at{0, 0.25, 0};
  Image photo = constant_photo(0.4);
  LocalRadiance light = sky({0.5, 0.5, 0.5}, {3000, 3000, 3000}, at);
  geometry::TriMesh object = render::make_object({"blob", 0.4, 4000, at});
  const geometry::Camera cam = frame_camera({0, 0.45, 1.4}, at, 25);
  auto cpu = cpu_reference(photo, cam, light, object, render::Material{{0.7, 0.7, 0.7}, {0, 0, 0}});
  CompositeDesc with, without;
  without.gl.visibility_samples = 0;
  auto gl = augment::gl::composite(photo, cam, floor_mesh(), light, object, {0.7, 0.7, 0.7}, with);
  auto gl0 = augment::gl::composite(photo, cam, floor_mesh(), light, object, {0.7, 0.7, 0.7}, without);
  const double py = kH / 2.0;  // the blob's centre is the camera's target: the frame's centre row
  struct Half {
    double gl = 0, gl0 = 0, cpu = 0;
    int n = 0;
  } upper, lower;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (gl.mask.at(x, y, 0) == 1 && gl0.mask.at(x, y, 0) == 1 && cpu.mask.at(x, y, 0) == 1) {
        Half& h = y + 0.5 > py ? lower : upper;
        h.gl += gl.composite.rgb(x, y).y;
        h.gl0 += gl0.composite.rgb(x, y).y;
        h.cpu += cpu.composite.rgb(x, y).y;
        ++h.n;
      }
  ASSERT_GT(lower.n, 300);
  ASSERT_GT(upper.n, 300);
  std::printf(
      "blob over a floor, GL / CPU: lower half %.4f (unoccluded %.4f), upper half %.4f (%.4f), %d + %d pixels\n",
      lower.gl / lower.cpu, lower.gl0 / lower.cpu, upper.gl / upper.cpu, upper.gl0 / upper.cpu, lower.n, upper.n);
  EXPECT_NEAR(lower.gl / lower.cpu, 1.0, 0.015);
  EXPECT_NEAR(upper.gl / upper.cpu, 1.0, 0.015);
  // Without the factor the underside is lit by the floor as if the object cast no shadow on it.
  EXPECT_GT(lower.gl0 / lower.cpu, lower.gl / lower.cpu + 0.03);
}

TEST(AugmentGl, SoftVisibilityIsOneWhereNothingIsHidden) {
  // A sphere (convex: it hides nothing from itself) far above a small floor off to the side, under a
  // constant sky: every triangle receives all of its soft light, exactly (the ratio estimate of equal sums).
  geometry::TriMesh proxy = geometry::make_quad({5, -5, 0}, {0, 1, 0}, {0, 0, -1}, 0.5, 0.5);
  const Vec3 at{0, 0.3, 0};
  SoftVisibilityDesc alone;
  alone.pool_rays = 0;  // each triangle its own estimate
  for (const SoftVisibilityDesc& d : {alone, SoftVisibilityDesc{}}) {
    std::vector<Vec3> f = soft_visibility(sky({2, 2, 2}, {}, at), proxy, sphere_at(at, 0.6), d);
    ASSERT_EQ(f.size(), sphere_at(at, 0.6).triangle_count());
    int exact = 0;
    double worst = 0;
    for (const Vec3& v : f) {
      exact += v.x == 1 && v.y == 1 && v.z == 1;
      worst = std::max({worst, std::abs(v.x - 1), std::abs(v.y - 1), std::abs(v.z - 1)});
    }
    // Alone: exactly 1 where every sample is a distant patch; the few triangles that sampled the quad's patches
    // (seen nearer or farther than from the centre: parallax) and rays grazing a neighbouring facet are near 1.
    // Pooled with their neighbours (the default) more are near 1 and fewer exactly.
    std::printf("soft factor (pool %d rays) exactly 1 on %d of %zu triangles, at most %.5f from 1\n", d.pool_rays,
                exact, f.size(), worst);
    if (d.pool_rays == 0) EXPECT_GE(exact, static_cast<int>(f.size() * 0.95));
    EXPECT_LT(worst, d.pool_rays == 0 ? 0.01 : 0.002);
  }
  EXPECT_THROW(soft_visibility(sky({2, 2, 2}, {}, at), proxy, sphere_at(at, 0.6), SoftVisibilityDesc{0}), Error);
}

}  // namespace
}  // namespace ibl::augment::gl
