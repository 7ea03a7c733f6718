// Tests of the ILF pipeline: the closed-form light field of analytic.h (emitting spheres outside the
// volume + a sky, no occluders) resampled into an SH grid and compared with the exact SH at every grid
// point; the repair steps; the bucket store; bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "iblkit/core/error.h"
#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/build.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;

std::string temp_dir(const std::string& name) {
  auto d = fs::temp_directory_path() / fmt::format("iblkit_ilf_test_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

// A small capture of a field: 200 mirror balls of 32×32 at random positions in the unit cube.
std::string small_sequence(const AnalyticField& f, const std::string& name) {
  SynthDesc sd;
  sd.out_dir = temp_dir(name);
  sd.probes = 200;
  sd.size = 32;
  sd.half = true;
  return write_synthetic_sequence(f, sd);
}

struct GridError {
  double rel_l2 = 0;       // ‖c − c*‖ / ‖c*‖ over every point, coefficient and channel
  double worst_point = 0;  // max over points of ‖c − c*‖ / ‖c*‖ at that point
};

std::vector<sh::Coeffs> exact_at_grid(const GridDesc& gd, int bands, const Sequence& seq, const AnalyticField& f) {
  std::vector<Vec3> pts;
  for (int64_t i = 0; i < gd.count(); ++i) pts.push_back(gd.point(i));
  return f.exact_sh(pts, bands, seq, 96, 2);
}

GridError compare_with_exact(const SHGrid& g, const std::vector<sh::Coeffs>& exact) {
  const auto& gd = g.grid();
  double num = 0, den = 0, worst = 0;
  int K = g.coeff_count();
  for (int64_t i = 0; i < gd.count(); ++i) {
    const float* c = g.data().data() + size_t(i) * K * 3;
    double pn = 0, pd = 0;
    for (int kk = 0; kk < K; ++kk)
      for (int ch = 0; ch < 3; ++ch) {
        double d = c[3 * kk + ch] - exact[i].c[kk][ch];
        pn += d * d;
        pd += exact[i].c[kk][ch] * exact[i].c[kk][ch];
      }
    num += pn;
    den += pd;
    worst = std::max(worst, std::sqrt(pn / pd));
  }
  return {std::sqrt(num / den), worst};
}

BuildDesc small_build(Repair r, const std::string& name) {
  BuildDesc bd;
  bd.nx = bd.ny = bd.nz = 8;
  bd.bands = 5;
  bd.project.repair = r;
  bd.buckets.dir = temp_dir(name);
  bd.buckets.octahedral = -1;  // auto: pixel buckets for 32×32 frames
  return bd;
}

// A nearly parallax-free field: every grid point sees the same sky, so the grid must reproduce the
// exact SH to the accuracy of one 32×32 probe (half-float frames, 3×3 supersampled pixels).
TEST(IlfAnalytic, DistantFieldMatchesExactSH) {
  auto field = AnalyticField::distant();
  auto seq = read_sequence(small_sequence(field, "distant"));
  SHGrid g = build_shgrid(seq, small_build(Repair::PullPush, "distant_b"));
  auto e = compare_with_exact(g, exact_at_grid(g.grid(), g.bands(), seq, field));
  // Direct SH projection of probe 0's frame with exact pixel solid angles: what every grid point
  // should hold when all probes see the same thing.
  Image img = io::read_image(seq.probes[0].image);
  sphere::Mapping m(seq.mapping, img.width(), img.height(), seq.dead_angle_deg);
  std::vector<Vec3> direct(size_t(g.coeff_count()));
  std::vector<double> y(direct.size());
  for (int py = 0; py < img.height(); ++py)
    for (int px = 0; px < img.width(); ++px) {
      Vec3 d;
      if (!m.to_direction(px + 0.5, py + 0.5, &d)) continue;
      sh::eval_basis(g.bands(), d, y.data());
      for (size_t k = 0; k < y.size(); ++k) direct[k] += img.rgb(px, py) * (m.solid_angle(px, py) * y[k]);
    }
  double worst_vs_direct = 0, dn = 0;
  for (auto& c : direct) dn += dot(c, c);
  for (int64_t p = 0; p < g.grid().count(); ++p) {
    double n = 0;
    for (size_t k = 0; k < direct.size(); ++k)
      for (int ch = 0; ch < 3; ++ch) n += std::pow(g.data()[(p * direct.size() + k) * 3 + ch] - direct[k][ch], 2);
    worst_vs_direct = std::max(worst_vs_direct, std::sqrt(n / dn));
  }
  std::printf("[ilf] distant field: rel L2 %.4f, worst point %.4f; worst point vs one probe's projection %.5f\n",
              e.rel_l2, e.worst_point, worst_vs_direct);
  constexpr double kProbeTol = 0.04;      // one 32×32 mirror ball (3×3 supersampled) vs exact: ≈ 0.03 measured
  constexpr double kPipelineTol = 0.005;  // half-float frames and the field's residual parallax (spheres 1.3–2 km away)
  EXPECT_LT(e.rel_l2, kProbeTol);
  EXPECT_LT(e.worst_point, kProbeTol);
  EXPECT_LT(worst_vs_direct, kPipelineTol);
}

// Emitting spheres 1.3–2 m from the cube's centre: the SH varies strongly over the volume. The grid
// must follow it at every point, and be far better than a grid that ignores position.
TEST(IlfAnalytic, GridMatchesExactSH) {
  auto field = AnalyticField::three_spheres();
  auto seq = read_sequence(small_sequence(field, "near"));
  GridError blind{};
  std::vector<sh::Coeffs> exact;
  for (Repair r : {Repair::Mip, Repair::PullPush}) {
    BuildReport rep;
    SHGrid g = build_shgrid(seq, small_build(r, std::string("near_") + repair_name(r)), {}, &rep);
    if (exact.empty()) exact = exact_at_grid(g.grid(), g.bands(), seq, field);
    auto e = compare_with_exact(g, exact);
    if (r == Repair::Mip) {
      // Position-blind baseline: the grid's mean SH at every point.
      SHGrid mean = g;
      size_t n = size_t(g.coeff_count()) * 3, G = size_t(g.grid().count());
      for (size_t i = 0; i < n; ++i) {
        double s = 0;
        for (size_t p = 0; p < G; ++p) s += g.data()[p * n + i];
        for (size_t p = 0; p < G; ++p) mean.data()[p * n + i] = float(s / G);
      }
      blind = compare_with_exact(mean, exact);
    }
    std::printf("[ilf] repair %-8s rel L2 %.4f  worst point %.4f  uncovered %.4f  (position-blind %.4f)\n",
                repair_name(r), e.rel_l2, e.worst_point, rep.fraction_uncovered, blind.rel_l2);
    // 200 probes, kernel 3 cells of 1/7 m: the estimate blurs the light field over ≈ 0.1 m (σ), which
    // at 1.3–2 m moves the sphere edges by ≈ 4°; measured ≈ 0.12 overall, ≈ 0.31 at the worst point.
    constexpr double kRelL2Tol = 0.15;       // whole grid
    constexpr double kWorstPointTol = 0.40;  // any single grid point
    constexpr double kVsBlind = 0.5;         // at most half the position-blind grid's error
    EXPECT_LT(e.rel_l2, kRelL2Tol) << repair_name(r);
    EXPECT_LT(e.worst_point, kWorstPointTol) << repair_name(r);
    EXPECT_LT(e.rel_l2, kVsBlind * blind.rel_l2) << repair_name(r);
  }
}

}  // namespace
}  // namespace ibl::ilf
