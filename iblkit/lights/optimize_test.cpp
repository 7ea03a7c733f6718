#include "iblkit/lights/optimize.h"

#include <gtest/gtest.h>

#include "iblkit/lights/cut.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/test_probes.h"
#include "iblkit/sphere/pointset.h"

namespace ibl::lights {
namespace {

// Unit tests fit at the 1280 normals of a level-3 icosphere (the CLI default is level 5).
constexpr int kLevel = 3;

struct Fit {
  LightSet set;
  OptimizeReport rep;
  ErrorStats err, init_err;
};

Fit fit(const sphere::EnvMap& env, int n) {
  auto normals = sphere::icosphere_face_centres(kLevel);
  auto gt = irradiance_ground_truth(env, normals);
  CutDesc cd;
  cd.count = n;
  auto init = variance_cut(env, cd);
  OptimizeDesc od;
  Fit f;
  f.set = optimize_lights_from(env, normals, gt, init.lights, od, &f.rep);
  f.err = compare_irradiance(irradiance_from_lights(f.set.lights, normals), gt);
  f.init_err = compare_irradiance(irradiance_from_lights(init.lights, normals), gt);
  return f;
}

TEST(LightsOptimize, FindsASunFromAFarStart) {
  // One lit pixel; the start is 20° off with twice the irradiance. The fitted light must land on the
  // pixel centre: the residual is exactly zero there, so LM gets to 1e−6 (its tolerances) or better.
  constexpr double kTol = 1e-5;
  auto env = testing::sun_probe(64, 32, 20, 10, {30, 20, 10});
  sphere::Mapping m = env.mapping;
  Vec3 d;
  m.to_direction(20.5, 10.5, &d);
  double dw = m.solid_angle(20, 10);
  Frame fr = Frame::from_normal(d);
  Light start{normalize(fr.n * std::cos(0.35) + fr.t * std::sin(0.35)), Vec3{60, 40, 20} * dw, 0};
  auto normals = sphere::icosphere_face_centres(kLevel);
  auto gt = irradiance_ground_truth(env, normals);
  OptimizeReport rep;
  auto set = optimize_lights_from(env, normals, gt, {start}, OptimizeDesc{}, &rep);
  ASSERT_EQ(set.lights.size(), 1u);
  EXPECT_GT(dot(set.lights[0].direction, d), std::cos(kTol));
  EXPECT_NEAR(set.lights[0].irradiance.x, 30 * dw, kTol * 30 * dw);
  EXPECT_LT(rep.final_cost, 1e-6 * rep.initial_cost);
}

TEST(LightsOptimize, UnitRadianceWithinPedersensFigures) {
  // Pedersen 2008 Table 7.1 (median cut, unit radiance): 16 lights average 3.046 / RMS 0.241,
  // 64 lights 3.108 / RMS 0.050. The optimiser must match or beat both.
  struct Row {
    int n;
    double mean_irr, rms;
  };
  const Row kPedersen[] = {{16, 3.046, 0.241}, {64, 3.108, 0.050}};
  auto env = testing::constant_probe(128, 64);
  for (const auto& row : kPedersen) {
    auto f = fit(env, row.n);
    EXPECT_LE(std::abs(luminance(f.err.mean_est) - kPi), kPi - row.mean_irr) << "N=" << row.n;
    EXPECT_LE(f.err.rms_abs, row.rms) << "N=" << row.n;
  }
}

TEST(LightsOptimize, BeatsMedianCutAndNeverWorseOnBlenderProbes) {
  auto probes = testing::blender_probes();
  if (probes.empty()) GTEST_SKIP() << "blender-data not installed";
  auto normals = sphere::icosphere_face_centres(kLevel);
  for (const auto& p : probes) {
    auto env = testing::small_probe(p, 128, 64);
    auto gt = irradiance_ground_truth(env, normals);
    for (int n : {2, 3, 4, 8, 16}) {
      auto f = fit(env, n);
      CutDesc cd;
      cd.count = n;
      auto mc = compare_irradiance(irradiance_from_lights(median_cut(env, cd).lights, normals), gt);
      EXPECT_LT(f.err.mean_rel, mc.mean_rel) << p << " N=" << n;
      // Never worse than the initialisation: not in its objective, not in the reported error.
      EXPECT_LE(f.rep.final_cost, f.rep.initial_cost) << p << " N=" << n;
      EXPECT_LE(f.err.mean_rel, f.init_err.mean_rel) << p << " N=" << n;
      // The mean irradiance over the sphere of normals stays within the fit's own (RMS relative) error.
      for (int c = 0; c < 3; ++c)
        EXPECT_LE(std::abs(f.err.mean_est[c] - f.err.mean_gt[c]), f.err.rms_rel * f.err.mean_gt[c] + 1e-12)
            << p << " N=" << n;
    }
  }
}

TEST(LightsOptimize, RotatingTheProbeRotatesTheLights) {
  // Three unequal lobes rotated by 37° about (1,2,3): the fitted lights follow within 1.5°. The fit
  // lands where the residuals at the 1280 normals (~6° apart) balance, and the rotation moves the lobes
  // relative to those normals, so the optimum moves by a fraction of their spacing.
  constexpr double kAngleTol = 1.5 * kPi / 180;
  auto env = testing::lobe_probe(512, 256, {{0.2, 0.9, 0.3}, {-0.7, 0.2, 0.5}, {0.4, -0.3, -0.8}},
                                 {{8, 6, 4}, {2, 5, 3}, {1, 1, 6}}, 0.05);
  Mat3 R = Mat3::rotation({1, 2, 3}, 37 * kPi / 180);
  sphere::ResampleDesc rd;
  rd.rotation = R;
  sphere::EnvMap rot(sphere::resample(env, env.mapping, rd), env.mapping);
  auto a = fit(env, 3), b = fit(rot, 3);
  for (const auto& la : a.set.lights) {
    Vec3 want = R * la.direction;
    double best = -1;
    for (const auto& lb : b.set.lights) best = std::max(best, dot(lb.direction, want));
    EXPECT_GT(best, std::cos(kAngleTol));
  }
}

TEST(LightsOptimize, ConvergesByItsStoppingRuleAtEveryScale) {
  // N = 1, 2, 16, 64 on a small real probe (64×32 forest, 1280 normals): every fit must end by the
  // stopping rule (not the iteration cap), below its start, and stay where it is when restarted from
  // its own answer with a 1000× tighter tolerance: the mean error may then move only in its 3rd
  // significant figure.
  auto probes = testing::blender_probes();
  std::string path;
  for (const auto& p : probes)
    if (p.find("forest") != std::string::npos) path = p;
  if (path.empty()) GTEST_SKIP() << "blender-data not installed";
  auto env = testing::small_probe(path, 64, 32);
  auto normals = sphere::icosphere_face_centres(kLevel);
  auto gt = irradiance_ground_truth(env, normals);
  constexpr double kThirdFigure = 5e-3;  // relative change of the mean error that leaves 3 significant figures alone
  for (int n : {1, 2, 16, 64}) {
    CutDesc cd;
    cd.count = n;
    auto init = variance_cut(env, cd);
    OptimizeDesc od;
    od.max_iterations = 400;  // far above what convergence takes here; hitting it fails the test
    OptimizeReport rep;
    auto set = optimize_lights_from(env, normals, gt, init.lights, od, &rep);
    EXPECT_TRUE(rep.converged) << "N=" << n << ": " << rep.termination;
    EXPECT_LT(rep.final_iterations, od.max_iterations) << "N=" << n;
    EXPECT_LE(rep.final_cost, rep.initial_cost) << "N=" << n;
    auto err = compare_irradiance(irradiance_from_lights(set.lights, normals), gt);
    OptimizeDesc tight = od;
    tight.tolerance = od.tolerance * 1e-3;
    tight.coarse_to_fine = false;
    OptimizeReport rep2;
    auto again = optimize_lights_from(env, normals, gt, set.lights, tight, &rep2);
    auto err2 = compare_irradiance(irradiance_from_lights(again.lights, normals), gt);
    EXPECT_NEAR(err2.mean_rel, err.mean_rel, kThirdFigure * err.mean_rel) << "N=" << n;
    EXPECT_LE(rep2.final_cost, rep.final_cost * (1 + 1e-12)) << "N=" << n;  // restart never ends worse
  }
}

TEST(LightsOptimize, BadInputIsRejected) {
  auto black = testing::constant_probe(32, 16, 0.0f);
  OptimizeDesc d;
  d.count = 2;
  d.normals_level = 2;
  EXPECT_THROW(optimize_lights(black, d), Error);
  auto env = testing::constant_probe(32, 16);
  d.count = 0;
  EXPECT_THROW(optimize_lights(env, d), Error);
  d.count = 2;
  d.init = "k-means";
  EXPECT_THROW(optimize_lights(env, d), Error);
}

}  // namespace
}  // namespace ibl::lights
