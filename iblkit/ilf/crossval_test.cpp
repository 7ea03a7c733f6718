// Tests of the cross-validation (ilf/crossval.h): zero on a field every grid represents exactly, the
// one-pass difference of fold rasters equal to k separate builds, the automatic choice, the error
// volume, and shares of the blocks (a distributed job's, CvShare) that add up to the whole.
#include <gtest/gtest.h>

#include <barrier>
#include <cmath>
#include <filesystem>
#include <thread>

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
  std::printf("[ilf] three spheres, 120 probes, 4^3: cv error one pass %.5f, five separate builds %.5f\n",
              rep.crossval->rel_error, brute);
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
  // The colours: 0 black, max_error red, and grey (neither) where less than one probe's weight is near.
  Image e(3, 1, 3);
  e.set_rgb(0, 0, {0.0, 0, 5});
  e.set_rgb(1, 0, {0.5, 1, 5});
  e.set_rgb(2, 0, {0.0, 0, 0.4});
  Image c = error_colours(e, 0.5);
  EXPECT_EQ(c.rgb(0, 0).x + c.rgb(0, 0).y + c.rgb(0, 0).z, 0);
  EXPECT_NEAR(c.rgb(1, 0).x, std::pow(0.9, 2.2), 1e-6);
  EXPECT_NEAR(c.rgb(1, 0).y, std::pow(0.1, 2.2), 1e-6);
  EXPECT_NEAR(c.rgb(2, 0).x, std::pow(0.45, 2.2), 1e-6);
  EXPECT_EQ(c.rgb(2, 0).x, c.rgb(2, 0).z);
  // Grid auto: a resolution among the candidates, within memory.
  BuildDesc b3 = cv_build(8, temp_dir("auto_b"));
  b3.auto_grid = true;
  BuildReport r3;
  build_shgrid(seq, b3, {}, &r3);
  ASSERT_TRUE(r3.choice);
  EXPECT_NE(std::find(std::begin(kAutoGrids), std::end(kAutoGrids), r3.nx), std::end(kAutoGrids));
}

// A focus (where an object will be lit) weights the probes around it: the closed form on two probes,
// one at the centre and one beyond 3σ; then a build whose choice is the least error there (not the
// whole volume's, which it reports beside), and a focus no probe is near is refused.
TEST(IlfCrossVal, FocusChoosesForTheNeighbourhood) {
  CrossValResult r;
  r.positions = {{0.5, 0.5, 0.5}, {0.5, 0.5, 0.95}, {0.05, 0.05, 0.05}};
  r.sq_error = {1, 0, 100};
  r.sq_norm = {4, 0, 1};
  const Box unit{{0, 0, 0}, {1, 1, 1}};
  Focus f{{0.5, 0.5, 0.5}, 0.1};
  EXPECT_NEAR(focus_sigma(f, unit, 3), std::cbrt(1.0 / 3), 1e-12);  // the probe spacing beats the radius
  Focus tight{{0.5, 0.5, 0.5}, 0};
  Box wide{{0, 0, 0}, {0.3, 0.3, 0.3}};  // σ = (0.027/3)^⅓ ≈ 0.21: 3σ ≈ 0.62 excludes the corner probe (0.78 away)
  double w = 0;
  double sigma = focus_sigma(tight, wide, 3);
  double k = std::exp(-0.45 * 0.45 / (2 * sigma * sigma));  // the probe 0.45 above: weight k, no error, no norm
  EXPECT_NEAR(focus_error(r, tight, wide, &w), std::sqrt(1.0 / 4), 1e-12);
  EXPECT_NEAR(w, 1 + k, 1e-12);
  Focus nowhere{{5, 5, 5}, 0};
  EXPECT_TRUE(std::isnan(focus_error(r, nowhere, wide)));

  auto field = AnalyticField::three_spheres();
  auto seq = capture(field, "focus", 150, 16);
  BuildDesc bd = cv_build(8, temp_dir("focus_b"));
  bd.auto_kernel = true;
  const Vec3 lo = seq.volume.min, sz = seq.volume.size();
  bd.focus = Focus{lo + Vec3{0.25 * sz.x, 0.3 * sz.y, 0.7 * sz.z}, 0};
  BuildReport rep;
  build_shgrid(seq, bd, {}, &rep);
  ASSERT_TRUE(rep.choice && rep.choice->focus);
  const auto& ch = *rep.choice;
  ASSERT_EQ(ch.trials.size(), std::size(kAutoKernels));
  size_t by_focus = 0, by_volume = 0;
  for (size_t i = 0; i < ch.trials.size(); ++i) {
    EXPECT_TRUE(std::isfinite(ch.trials[i].focus_error));
    if (ch.trials[i].focus_error < ch.trials[by_focus].focus_error) by_focus = i;
    if (ch.trials[i].cv_error < ch.trials[by_volume].cv_error) by_volume = i;
  }
  std::printf("[ilf] focus: chosen %g cells (error there %.4f), the volume's choice %g (%.4f)\n", rep.kernel_cells,
              ch.trials[by_focus].focus_error, ch.volume_kernel, ch.trials[by_volume].cv_error);
  EXPECT_EQ(ch.chosen, by_focus);
  EXPECT_EQ(rep.kernel_cells, ch.trials[by_focus].kernel);
  EXPECT_EQ(ch.volume_kernel, ch.trials[by_volume].kernel);
  EXPECT_NEAR(rep.crossval->rel_error, ch.trials[by_focus].cv_error, 1e-6);  // the chosen trial's cross-validation
  EXPECT_NEAR(focus_error(*rep.crossval, *bd.focus, seq.volume), ch.trials[by_focus].focus_error, 1e-9);
  EXPECT_GT(ch.focus_weight, 1);
  // Refused: a focus far outside every probe, and a focus with nothing to choose.
  BuildDesc far = bd;
  far.buckets.dir = temp_dir("focus_far");
  far.focus = Focus{seq.volume.max + 10 * sz, 0};
  try {
    build_shgrid(seq, far);
    ADD_FAILURE() << "a focus no probe is near was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no probe"), std::string::npos) << e.what();
  }
  BuildDesc fixed = bd;
  fixed.auto_kernel = false;
  EXPECT_THROW(build_shgrid(seq, fixed), Error);
}

// A job of N processes, here N threads of this one: each evaluates its share of the blocks (contiguous
// ranges, one of them empty) and `sum` adds the partial sums through shared memory. The job's error,
// its per-probe figures and its automatic choice equal one process's to float rounding of the sum in
// double, with the buckets sampled (every 5th: max_buckets 100 of ~440) by their global index.
// A capture with a gap: 64 probes (relative error 0.2 each) in the corner x, y, z < 0.25 of a unit
// cube. The error volume's slice through z = 0.1 gives 0.2 in the corner and no weight in the far one,
// which error_colours draws grey — not black, which would read as "no error".
TEST(IlfCrossVal, ErrorVolumeShowsAGapAsNoFigure) {
  CrossValResult r;
  for (int i = 0; i < 64; ++i) {
    r.positions.push_back({0.05 + 0.05 * (i % 4), 0.05 + 0.05 * (i / 4 % 4), 0.05 + 0.05 * (i / 16)});
    r.sq_error.push_back(0.04);
    r.sq_norm.push_back(1.0);
  }
  GridDesc g{16, 16, 16, {{0, 0, 0}, {1, 1, 1}}};
  SHGrid ev = error_volume(r, g);
  Image e = error_slice(ev, 2, 0.1, 16);
  ASSERT_EQ(e.height(), 16);
  EXPECT_NEAR(e.at(1, 14, 0), 0.2, 1e-5);  // image x along x, image y down y: (x, y) ≈ (0.09, 0.09)
  EXPECT_GT(e.at(1, 14, 2), 1.0);
  EXPECT_EQ(e.at(14, 1, 2), 0.0f);  // (0.91, 0.91): beyond 3σ of every probe
  EXPECT_EQ(e.at(14, 1, 0), 0.0f);
  Image c = error_colours(e, 0.5);
  const float grey = float(std::pow(0.45, 2.2));
  EXPECT_NEAR(c.at(14, 1, 0), grey, 1e-6);
  EXPECT_NEAR(c.at(14, 1, 1), grey, 1e-6);
  EXPECT_GT(c.at(1, 14, 1), 0.2f);  // 0.2 of 0.5: between blue and green (green 0.56 before encoding)
  EXPECT_LT(c.at(1, 14, 0), 0.05f);
}

TEST(IlfCrossVal, SharesOfTheBlocksAddUpToTheWhole) {
  auto field = AnalyticField::three_spheres();
  auto seq = capture(field, "share", 60, 24);
  BucketDesc bd;
  bd.dir = temp_dir("share_b");
  BucketStore store = BucketStore::sort(seq, bd);
  const int blocks = store.table().blocks();
  ASSERT_GE(blocks, 4);
  std::vector<Vec3> origins;
  for (const auto& p : seq.probes) origins.push_back(p.position);
  GridDesc grid{6, 6, 6, seq.volume};
  ProjectDesc pd;
  CrossValDesc cvd;
  constexpr int kMaxBuckets = 100;
  ResampleSearch rs{.kernel = true, .volume = seq.volume, .nx = 6, .ny = 6, .nz = 6, .max_buckets = kMaxBuckets};
  int used = 0;
  CrossValResult whole = cross_validate(store, origins, grid, pd, 5, cvd, kMaxBuckets, true, &used);
  ResampleChoice whole_choice = choose_resampling(store, origins, pd, rs, cvd, true);
  EXPECT_LT(used, store.table().buckets() / 4);  // sampled, not every bucket
  // Blocks [0, 1), [1, 1) (none), [1, blocks/2), [blocks/2, blocks).
  const std::vector<int> cut = {0, 1, 1, blocks / 2, blocks};
  const int N = int(cut.size()) - 1;
  std::barrier sync(N);
  std::vector<double*> parts(size_t(N), nullptr);
  std::vector<double> total;
  auto sum_of = [&](int rank) {
    return [&, rank](double* x, size_t n) {
      parts[rank] = x;
      sync.arrive_and_wait();
      if (rank == 0) {
        total.assign(n, 0.0);
        for (double* q : parts)
          for (size_t i = 0; i < n; ++i) total[i] += q[i];
      }
      sync.arrive_and_wait();
      std::copy(total.begin(), total.end(), x);
      sync.arrive_and_wait();
    };
  };
  std::vector<CrossValResult> res(static_cast<size_t>(N));
  std::vector<ResampleChoice> choice(static_cast<size_t>(N));
  std::vector<int> used_by(static_cast<size_t>(N));
  {
    std::vector<std::jthread> ranks;
    for (int r = 0; r < N; ++r)
      ranks.emplace_back([&, r] {
        CvShare share{cut[r], cut[r + 1], {}, sum_of(r)};
        res[r] = cross_validate(store, origins, grid, pd, 5, cvd, kMaxBuckets, true, &used_by[r], share);
        choice[r] = choose_resampling(store, origins, pd, rs, cvd, true, share);
      });
  }
  auto rel = [](double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); };
  for (int r = 0; r < N; ++r) {
    EXPECT_EQ(used_by[r], used);
    EXPECT_EQ(res[r].evaluated, whole.evaluated);
    EXPECT_LT(rel(res[r].rel_error, whole.rel_error), 1e-9) << r;
    EXPECT_LT(rel(res[r].median_probe_error, whole.median_probe_error), 1e-9) << r;
    ASSERT_EQ(res[r].sq_error.size(), whole.sq_error.size());
    for (size_t e = 0; e < whole.sq_error.size(); ++e) {
      EXPECT_LT(rel(res[r].sq_error[e], whole.sq_error[e]), 1e-9) << r << " probe " << e;
      EXPECT_LT(rel(res[r].sq_norm[e], whole.sq_norm[e]), 1e-9) << r << " probe " << e;
    }
    EXPECT_EQ(choice[r].kernel, whole_choice.kernel);
    EXPECT_EQ(choice[r].buckets_used, whole_choice.buckets_used);
    ASSERT_EQ(choice[r].trials.size(), whole_choice.trials.size());
    for (size_t i = 0; i < whole_choice.trials.size(); ++i)
      EXPECT_LT(rel(choice[r].trials[i].cv_error, whole_choice.trials[i].cv_error), 1e-9) << r << " trial " << i;
    for (size_t i = 0; i < whole.region_error.size(); ++i)
      if (std::isfinite(whole.region_error[i])) {
        EXPECT_LT(rel(res[r].region_error[i], whole.region_error[i]), 1e-9);
      }
  }
  // Every rank holds the same bits (the ranks must make the same choice).
  for (int r = 1; r < N; ++r) EXPECT_EQ(res[r].rel_error, res[0].rel_error);
  std::printf("[ilf] cv over %d shares of %d blocks, %d of %d buckets: %.9f (one process %.9f), kernel %g\n", N, blocks,
              used, store.table().buckets(), res[0].rel_error, whole.rel_error, choice[0].kernel);
}

}  // namespace
}  // namespace ibl::ilf
