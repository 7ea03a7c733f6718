#include "iblkit/lights/extract.h"
#include "iblkit/core/testing.h"

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "iblkit/core/error.h"
#include "iblkit/lights/cut.h"
#include "iblkit/lights/test_probes.h"
#include "iblkit/sphere/pointset.h"

using ibl::test_util::expect_error;

namespace ibl::lights {
namespace {

namespace fs = std::filesystem;

// Three coloured lobes on black: every method finds light, and the cuts are deterministic.
sphere::EnvMap lobes() {
  return testing::lobe_probe(64, 32, {{0.3, 0.9, 0.2}, {-0.7, 0.4, -0.5}, {0.2, -0.3, 0.9}},
                             {{5, 4, 3}, {1, 2, 3}, {0.5, 0.5, 0.2}});
}

void expect_same_lights(const LightSet& a, const LightSet& b) {
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(a.lights[i].direction[c], b.lights[i].direction[c]) << i;
      EXPECT_EQ(a.lights[i].irradiance[c], b.lights[i].irradiance[c]) << i;
    }
    EXPECT_EQ(a.lights[i].solid_angle, b.lights[i].solid_angle) << i;
  }
}

TEST(LightsExtract, EachMethodIsItsCut) {
  auto env = lobes();
  CutDesc cd;
  cd.count = 8;
  ExtractDesc ed;
  ed.count = 8;
  ed.method = "median-cut";
  auto mc = extract(env, ed);
  expect_same_lights(mc.set, median_cut(env, cd));
  EXPECT_EQ(mc.set.method, "median-cut");
  EXPECT_EQ(mc.normals, 0);  // a cut fits no normals
  EXPECT_GE(mc.seconds, 0);
  ed.method = "variance-cut";
  expect_same_lights(extract(env, ed).set, variance_cut(env, cd));
  ed.method = "median-cut-2k";
  cd.power_of_two = true;
  auto m2 = extract(env, ed);
  expect_same_lights(m2.set, median_cut(env, cd));
  EXPECT_EQ(m2.set.method, "median-cut-2k");
}

TEST(LightsExtract, OptimizeStartsFromItsInitialCut) {
  auto env = lobes();
  ExtractDesc ed;
  ed.method = "optimize";
  ed.count = 4;
  ed.optimize.normals_level = 2;
  ed.optimize.coarse_to_fine = false;
  ed.optimize.init = "median-cut";
  auto normals = sphere::icosphere_face_centres(2);
  auto gt = irradiance_ground_truth(env, normals);
  OptimizeDesc od = ed.optimize;
  od.count = 4;
  OptimizeReport rep;
  auto direct = optimize_lights_from(env, normals, gt, initial_lights(env, od).lights, od, &rep);
  // Given targets and the targets extract computes itself (level 2: 320 normals) give the same lights.
  auto given = extract(env, ed, normals, gt);
  auto own = extract(env, ed);
  expect_same_lights(given.set, direct);
  expect_same_lights(own.set, direct);
  EXPECT_EQ(given.normals, 320);
  EXPECT_EQ(own.normals, 320);
  EXPECT_EQ(own.optimizer.iterations, rep.iterations);
  EXPECT_EQ(own.optimizer.final_cost, rep.final_cost);
}

TEST(LightsExtract, BadSettingsAreNamed) {
  auto env = lobes();
  ExtractDesc ed;
  ed.method = "k-means";
  expect_error([&] { extract(env, ed); },
               "unknown method 'k-means': use median-cut, median-cut-2k, variance-cut, optimize");
  ed.method = "optimize";
  ed.optimize.normals_level = kMaxNormalsLevel + 1;
  expect_error([&] { extract(env, ed); }, "normals level must be in [0, 7] (got 8)");
  ed.optimize.normals_level = 2;
  auto normals = sphere::icosphere_face_centres(1);
  expect_error([&] { extract(env, ed, normals, {}); }, "80 normals but 0 ground-truth values");
  ed.count = 0;
  expect_error([&] { extract(env, ed); }, "light count");
  EXPECT_NO_THROW(check_method("median-cut-2k"));
  EXPECT_EQ(extraction_methods().size(), 4u);
}

TEST(LightsExtract, NormalsLevelRangeIsTheOptimisers) {
  // The lowest level the range admits works end to end: 20 normals (the icosahedron's faces).
  auto env = lobes();
  ExtractDesc ed;
  ed.method = "optimize";
  ed.count = 2;
  ed.optimize.normals_level = kMinNormalsLevel;
  ed.optimize.coarse_to_fine = false;
  EXPECT_EQ(extract(env, ed).normals, 20);
  EXPECT_NO_THROW(check_normals_level(kMaxNormalsLevel));
  EXPECT_THROW(check_normals_level(kMinNormalsLevel - 1), Error);
}

TEST(LightsEvaluateMethods, RowsPerMethodAndCountAgainstTheGroundTruth) {
  auto env = lobes();
  MethodsEvalDesc ev;
  ev.methods = {"median-cut", "median-cut-2k", "optimize"};
  ev.counts = {1, 3, 4};
  ev.normals_level = 2;
  ev.picture_count = 4;
  ev.optimize.coarse_to_fine = false;
  LightSet given = median_cut(env, CutDesc{2});
  given.method = "mine";
  ev.given = given;
  auto r = evaluate_methods(env, ev);
  EXPECT_EQ(r.normals, 320);
  // The given set first, then 3 + 2 (median-cut-2k skips N = 3) + 3 rows.
  ASSERT_EQ(r.rows.size(), 9u);
  EXPECT_EQ(r.rows[0].method, "mine (file)");
  EXPECT_EQ(r.rows[0].count, 2);
  EXPECT_EQ(r.rows[0].seconds, 0);
  EXPECT_EQ(r.rows[4].method, "median-cut-2k");
  EXPECT_EQ(r.rows[4].count, 1);
  EXPECT_EQ(r.rows[5].count, 4);
  for (const auto& row : r.rows) EXPECT_EQ(row.optimizer.has_value(), row.method == "optimize") << row.method;
  // Each row's errors are those of its set against the exact ground truth.
  auto normals = sphere::icosphere_face_centres(2);
  auto gt = irradiance_ground_truth(env, normals);
  auto mc3 = median_cut(env, CutDesc{3});
  auto err = compare_irradiance(irradiance_from_lights(mc3.lights, normals), gt);
  EXPECT_EQ(r.rows[2].method, "median-cut");
  EXPECT_EQ(r.rows[2].count, 3);
  EXPECT_EQ(r.rows[2].err.mean_rel, err.mean_rel);
  EXPECT_EQ(r.rows[2].err.max_rel, err.max_rel);
  // The optimiser ends below the cost it starts from.
  ASSERT_TRUE(r.rows[8].optimizer);
  EXPECT_LE(r.rows[8].optimizer->final_cost, r.rows[8].optimizer->initial_cost);
  // Pictures: each method's set at picture_count, and the given set.
  EXPECT_EQ(r.picture_sets.size(), 4u);
  EXPECT_EQ(r.picture_sets.at("optimize").lights.size(), 4u);
  EXPECT_EQ(r.picture_sets.at("mine").lights.size(), 2u);
  // The SH reference at the default 3 bands.
  EXPECT_TRUE(r.have_sh);
  EXPECT_EQ(r.sh_bands, 3);
  EXPECT_GT(r.sh.mean_rel, 0);
}

TEST(LightsEvaluateMethods, BadSettingsFailBeforeTheGroundTruth) {
  auto env = lobes();
  MethodsEvalDesc ev;
  ev.methods = {"median-cut", "nope"};
  expect_error([&] { evaluate_methods(env, ev); }, "unknown method 'nope'");
  ev.methods = {"median-cut"};
  ev.normals_level = -1;
  expect_error([&] { evaluate_methods(env, ev); }, "normals level");
  ev.normals_level = 1;
  ev.counts = {1, 0};
  expect_error([&] { evaluate_methods(env, ev); }, "light count");
}

std::string read_all(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(LightsEvaluateMethods, CsvNamesTheShReferenceByItsBands) {
  auto env = lobes();
  auto dir = fs::temp_directory_path() / ("iblkit_extract_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  MethodsEvalDesc ev;
  ev.methods = {"variance-cut", "optimize"};
  ev.counts = {2};
  ev.normals_level = 1;
  ev.optimize.coarse_to_fine = false;
  for (int bands : {2, 3, 5}) {
    ev.sh_bands = bands;
    auto r = evaluate_methods(env, ev);
    EXPECT_EQ(r.sh_bands, bands);
    auto p = dir / ("eval" + std::to_string(bands) + ".csv");
    write_eval_csv(p.string(), r);
    std::string csv = read_all(p);
    EXPECT_EQ(csv.rfind("method,count,mean_rel,max_rel,rms_rel,rms_abs,mean_irradiance_Y,seconds,iterations,"
                        "final_iterations,converged,initial_cost,final_cost\n",
                        0),
              0u);
    EXPECT_NE(csv.find("\nvariance-cut,2,"), std::string::npos) << csv;
    EXPECT_NE(csv.find("\noptimize,2,"), std::string::npos) << csv;
    std::string sh_row = "\n" + sh_reference_name(bands) + "," + std::to_string(bands * bands) + ",";
    EXPECT_NE(csv.find(sh_row), std::string::npos) << csv;
  }
  EXPECT_EQ(sh_reference_name(3), "sh-3band");
  ev.sh_bands = 0;
  auto r = evaluate_methods(env, ev);
  EXPECT_FALSE(r.have_sh);
  write_eval_csv((dir / "none.csv").string(), r);
  EXPECT_EQ(read_all(dir / "none.csv").find("\nsh-"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ibl::lights
