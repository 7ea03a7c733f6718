// Tests of the cross-validation (ilf/crossval.h): zero on a field every grid represents exactly, the
// one-pass difference of fold rasters equal to k separate builds, the automatic choice, the error
// volume.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/build.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/basis.h"

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;

std::string temp_dir(const std::string& name) {
  auto d = fs::temp_directory_path() / fmt::format("iblkit_ilfcv_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

Sequence capture(const AnalyticField& f, const std::string& name, int probes, int size) {
  SynthDesc sd;
  sd.out_dir = temp_dir(name);
  sd.probes = probes;
  sd.size = size;
  sd.supersample = 1;
  sd.half = false;  // float frames: the cross-validation of a constant field is then exact to float rounding
  return read_sequence(write_synthetic_sequence(f, sd));
}

BuildDesc cv_build(int n, const std::string& dir) {
  BuildDesc bd;
  bd.nx = bd.ny = bd.nz = n;
  bd.buckets.dir = dir;
  bd.crossval.folds = 5;
  return bd;
}

// Radiance that depends on the direction only (a sky, no spheres): every grid point holds the same
// SH, so the grid without any fold predicts every probe exactly — at a coarse grid where every corner
// has rays and at a fine one where most held-out probes fall back to the pyramid.
TEST(IlfCrossVal, ZeroOnAFieldTheGridRepresentsExactly) {
  AnalyticField sky;
  sky.spheres.clear();
  auto seq = capture(sky, "sky", 40, 16);
  for (int n : {4, 48}) {
    BuildReport rep;
    build_shgrid(seq, cv_build(n, temp_dir(fmt::format("sky_b{}", n))), {}, &rep);
    ASSERT_TRUE(rep.crossval);
    std::printf("[ilf] sky only, %d^3: cv error %.2e over %d probes (uncovered %.3f)\n", n, rep.crossval->rel_error,
                rep.crossval->evaluated, rep.fraction_uncovered);
    EXPECT_EQ(rep.crossval->evaluated, 40);
    EXPECT_LT(rep.crossval->rel_error, 1e-5) << n;
    if (n == 48) {
      EXPECT_GT(rep.fraction_uncovered, 0.3);  // the fallback was exercised
    }
  }
}

// The one-pass estimate (all folds' sum minus fold f's) against k separate builds from the other
// folds' probes, read at the held-out probes with SHGrid::coeffs_at and compared with each probe's own
// SH (its pixels' Σ Ω·Y·L): equal where every grid point has data (no repair involved).
TEST(IlfCrossVal, OnePassEqualsSeparateBuilds) {
  auto field = AnalyticField::three_spheres();
  auto seq = capture(field, "near", 120, 16);
  BuildDesc bd = cv_build(4, temp_dir("near_b"));
  BuildReport rep;
  build_shgrid(seq, bd, {}, &rep);
  ASSERT_TRUE(rep.crossval);
  ASSERT_EQ(rep.fraction_uncovered, 0.0);
  auto fold = assign_folds(int(seq.probes.size()), 5, bd.crossval.seed);
  auto t = make_direction_table(seq, 16, 16, BucketDesc{}, 1);
  int K = 25;
  std::vector<double> y(K);
  double num = 0, den = 0;
  for (int f = 0; f < 5; ++f) {
    Sequence rest = seq;
    rest.probes.clear();
    for (size_t p = 0; p < seq.probes.size(); ++p)
      if (fold[p] != f) rest.probes.push_back(seq.probes[p]);
    BuildDesc b2 = bd;
    b2.crossval.folds = 0;
    b2.buckets.dir = temp_dir(fmt::format("near_f{}", f));
    BuildReport r2;
    SHGrid g = build_shgrid(rest, b2, {}, &r2);
    ASSERT_EQ(r2.fraction_uncovered, 0.0);
    for (size_t p = 0; p < seq.probes.size(); ++p) {
      if (fold[p] != f) continue;
      Image img = io::read_image(seq.probes[p].image);
      std::vector<Vec3> own(K);
      for (int64_t s = 0; s < t.slots(); ++s) {
        sh::eval_basis(5, normalize(Vec3{t.dir[3 * s], t.dir[3 * s + 1], t.dir[3 * s + 2]}), y.data());
        Vec3 L = img.rgb(t.pixel[s] % 16, t.pixel[s] / 16);
        for (int k = 0; k < K; ++k) own[k] += L * (t.weight[s] * y[k]);
      }
      auto c = g.coeffs_at(seq.probes[p].position);
      for (int k = 0; k < K; ++k) {
        Vec3 d = c.c[k] - own[k];
        num += dot(d, d);
        den += dot(own[k], own[k]);
      }
    }
  }
  double brute = std::sqrt(num / den);
  std::printf("[ilf] three spheres, 120 probes, 4^3: cv error one pass %.5f, five separate builds %.5f\n", rep.crossval->rel_error, brute);
  EXPECT_GT(brute, 0.01);  // a field with parallax: not trivially zero
  EXPECT_NEAR(rep.crossval->rel_error, brute, 1e-3 * brute);
}

TEST(IlfCrossVal, AutoChoiceAndErrorVolume) {
  auto field = AnalyticField::three_spheres();
  auto seq = capture(field, "auto", 150, 16);
  BuildDesc bd = cv_build(8, temp_dir("auto_b"));
  bd.auto_kernel = true;
  BuildReport rep;
  SHGrid g = build_shgrid(seq, bd, {}, &rep);
  ASSERT_TRUE(rep.choice);
  ASSERT_EQ(rep.choice->trials.size(), std::size(kAutoKernels));
  double best = 1e300;
  for (const auto& t : rep.choice->trials) best = std::min(best, t.cv_error);
  for (const auto& t : rep.choice->trials) {
    if (t.kernel == rep.kernel_cells) {
      EXPECT_EQ(t.cv_error, best);
    }
  }
  EXPECT_EQ(rep.choice->buckets_used, rep.buckets);  // 16×16 frames: fewer buckets than the cap, all used
  // The chosen kernel's full cross-validation equals its trial's (both use every bucket here).
  for (const auto& t : rep.choice->trials) {
    if (t.kernel == rep.kernel_cells) {
      EXPECT_NEAR(rep.crossval->rel_error, t.cv_error, 1e-6);
    }
  }
  // Per region: octants, each with probes, the overall error between the least and the largest.
  ASSERT_EQ(rep.crossval->region_error.size(), 8u);
  double lo = 1e300, hi = 0;
  for (double e : rep.crossval->region_error) lo = std::min(lo, e), hi = std::max(hi, e);
  EXPECT_LE(lo, rep.crossval->rel_error);
  EXPECT_GE(hi, rep.crossval->rel_error);
  SHGrid ev = error_volume(*rep.crossval, g.grid());
  EXPECT_EQ(ev.content(), "cv-error");
  EXPECT_EQ(ev.bands(), 1);
  std::string f = temp_dir("auto_e") + "/e.shgrid";
  write_shgrid(f, ev);
  EXPECT_THROW(read_shgrid(f), Error);  // not lighting
  SHGrid back = read_shgrid(f, true);
  EXPECT_EQ(back.content(), "cv-error");
  EXPECT_EQ(back.data(), ev.data());
  double mean = 0;
  for (int64_t i = 0; i < ev.grid().count(); ++i) mean += ev.data()[size_t(i) * 3] / double(ev.grid().count());
  EXPECT_GT(mean, 0.3 * rep.crossval->rel_error);
  EXPECT_LT(mean, 3 * rep.crossval->rel_error);
  // Grid auto: a resolution among the candidates, within memory.
  BuildDesc b3 = cv_build(8, temp_dir("auto_b"));
  b3.auto_grid = true;
  BuildReport r3;
  build_shgrid(seq, b3, {}, &r3);
  ASSERT_TRUE(r3.choice);
  EXPECT_NE(std::find(std::begin(kAutoGrids), std::end(kAutoGrids), r3.nx), std::end(kAutoGrids));
}

}  // namespace
}  // namespace ibl::ilf
