// The distributed ILF build against the serial one: `mpirun --oversubscribe -np N iblkit
// ilf build …` for N = 1, 2, 3 gives the serial build's coefficients to float rounding, fails on a bad
// frame with the serial build's message once (or skips it with --skip-bad) without hanging, and a
// re-run reuses the buckets. Runs the iblkit command beside this test binary under mpirun; skips
// where mpirun is absent. Open MPI refuses root unless told; the allowance goes to mpirun's own
// environment only.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/build.h"

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;

constexpr double kRelTol = 1e-6;  // the "relative 1e-6 on every coefficient" (float rounding)
constexpr int kTimeout = 120;     // seconds before a run counts as hung

std::string iblkit_command() {
  auto exe = fs::read_symlink("/proc/self/exe").parent_path() / "iblkit";
  return fs::exists(exe) ? exe.string() : "";
}

bool have_mpirun() { return std::system("command -v mpirun >/dev/null 2>&1") == 0; }

struct Run {
  int status = -1;
  std::string out;
};

Run run(const std::string& cmd) {
  Run r;
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

Run mpirun(int ranks, const std::string& args) {
  return run(fmt::format(
      "timeout {} env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
      "mpirun --oversubscribe -np {} {} --quiet ilf build {}",
      kTimeout, ranks, iblkit_command(), args));
}

class IlfMpi : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_mpirun()) GTEST_SKIP() << "mpirun is absent (install openmpi-bin): the distributed build is not tested";
    if (iblkit_command().empty()) GTEST_SKIP() << "no iblkit command beside the test binary";
    dir_ =
        (fs::temp_directory_path() /
         fmt::format("iblkit_mpi_{}_{}", ::testing::UnitTest::GetInstance()->current_test_info()->name(), ::getpid()))
            .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    SynthDesc sd;
    sd.out_dir = dir_ + "/seq";
    sd.probes = 61;
    sd.size = 16;
    sd.supersample = 1;
    manifest_ = write_synthetic_sequence(AnalyticField::three_spheres(), sd);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // The serial build of the same options, in this process.
  SHGrid serial(BuildDesc bd, bool skip_bad = false) {
    bd.buckets.dir = dir_ + "/serial.buckets";
    bd.buckets.skip_bad = skip_bad;
    SequenceReadDesc rd;
    rd.skip_bad = skip_bad;
    return build_shgrid(read_sequence(manifest_, rd), bd);
  }
  // Returns the worst relative difference (−1 when the sizes differ).
  double expect_same(const SHGrid& a, const std::string& path, const std::string& what, bool error_volume = false) {
    SHGrid b = read_shgrid(path, error_volume);
    EXPECT_EQ(a.data().size(), b.data().size()) << what;
    if (a.data().size() != b.data().size()) return -1;
    int bad = 0;
    double worst = 0;
    for (size_t i = 0; i < a.data().size(); ++i) {
      double x = a.data()[i], y = b.data()[i], d = std::abs(x - y);
      if (d > kRelTol * std::abs(x)) ++bad;
      if (x != 0) worst = std::max(worst, d / std::abs(x));
    }
    EXPECT_EQ(bad, 0) << what << ": " << bad << " of " << a.data().size()
                      << " coefficients differ by more than 1e-6 (worst " << worst << ")";
    return worst;
  }
  std::string dir_, manifest_;
};

TEST_F(IlfMpi, SameGridAsSerialOnOneTwoThreeRanks) {
  struct Case {
    std::string args;
    BuildDesc bd;
  };
  BuildDesc pixel;
  pixel.nx = pixel.ny = pixel.nz = 6;
  pixel.buckets.octahedral = 0;
  BuildDesc oct = pixel;
  oct.buckets.octahedral = 6;
  oct.project.repair = Repair::PullPush;
  oct.bands = 3;
  BuildDesc sub = pixel;
  sub.subsample = SubsampleDesc{0.5, 0.5};
  // A fixed kernel without cross-validation (the CLI's default cross-validates: next test).
  std::vector<Case> cases = {
      {"--grid 6 --directions pixel --kernel 3 --cv-folds 0", pixel},
      {"--grid 6 --directions 6 --repair pullpush --bands 3 --kernel 3 --cv-folds 0", oct},
      {"--grid 6 --directions pixel --subsample 0.5 --subsample-distance 0.5 --kernel 3 --cv-folds 0", sub}};
  for (const auto& c : cases) {
    SHGrid want = serial(c.bd);
    for (int n : {1, 2, 3}) {
      std::string out = fmt::format("{}/g{}.shgrid", dir_, n);
      auto r = mpirun(n, fmt::format("{} {} --out {} --buckets {}/b{}", manifest_, c.args, out, dir_, n));
      ASSERT_EQ(r.status, 0) << c.args << ", " << n << " ranks:\n" << r.out;
      expect_same(want, out, fmt::format("{}, {} ranks", c.args, n));
    }
  }
}

// The cross-validation under MPI (docs/ilf.md "On a cluster"): the CLI's default (--kernel auto, 5
// folds), --grid auto (with the kernel), a fixed kernel's error, and --error-grid give the serial
// build's trials, choice, error, error volume and grid on 1, 2 and 3 ranks. 120 probes of 24² (444 pixel buckets, 7
// blocks: every bucket is evaluated) and of 64² (3228 buckets of 51 blocks, over BuildDesc::auto_max_buckets: every 2nd
// by its global index, whichever rank owns it).
TEST_F(IlfMpi, CrossValidationAndChoiceAsSerial) {
  struct Case {
    int size;
    std::string args;
    BuildDesc bd;
    std::vector<int> ranks;
  };
  BuildDesc kauto;  // the CLI's defaults at --grid 6
  kauto.nx = kauto.ny = kauto.nz = 6;
  kauto.auto_kernel = true;
  kauto.crossval.folds = 5;
  BuildDesc fixed = kauto;
  fixed.auto_kernel = false;
  fixed.project.kernel_cells = 2;
  fixed.crossval.folds = 4;
  BuildDesc both = kauto;  // and the grid: two rounds of candidates, the second chosen by the first
  both.auto_grid = true;
  both.buckets.memory_bytes = size_t(64) << 20;  // grids 8-24 (finer ones need more than half of it)
  std::vector<Case> cases = {{24, "--grid 6", kauto, {1, 2, 3}},
                             {24, "--grid 6 --kernel 2 --cv-folds 4", fixed, {3}},
                             {24, "--grid auto --memory 64M", both, {3}},
                             {64, "--grid 6", kauto, {3}}};
  std::map<int, std::string> seqs;
  for (int size : {24, 64}) {
    SynthDesc sd;
    sd.out_dir = fmt::format("{}/seq{}", dir_, size);
    sd.probes = 120;
    sd.size = size;
    sd.supersample = 1;
    seqs[size] = write_synthetic_sequence(AnalyticField::three_spheres(), sd);
  }
  for (const auto& c : cases) {
    BuildDesc bd = c.bd;
    bd.buckets.dir = fmt::format("{}/serial{}.buckets", dir_, c.size);
    BuildReport want;
    SHGrid grid = build_shgrid(read_sequence(seqs[c.size]), bd, {}, &want);
    ASSERT_TRUE(want.crossval);
    SHGrid ev = error_volume(*want.crossval, grid.grid());
    if (c.size == 64) {
      EXPECT_LT(2 * want.crossval_buckets, want.buckets + 2) << "the buckets were not sampled";
    }
    for (int n : c.ranks) {
      std::string what = fmt::format("{}² frames, {}, {} ranks", c.size, c.args, n);
      std::string out = fmt::format("{}/cv{}.shgrid", dir_, n), err = fmt::format("{}/cv{}.err.shgrid", dir_, n);
      auto t0 = std::chrono::steady_clock::now();
      auto r = mpirun(n, fmt::format("{} {} --json --out {} --error-grid {} --buckets {}/cvb{}_{}", seqs[c.size],
                                     c.args, out, err, dir_, c.size, n));
      ASSERT_EQ(r.status, 0) << what << ":\n" << r.out;
      double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      nlohmann::json j;
      ASSERT_NO_THROW(j = nlohmann::json::parse(r.out.substr(r.out.find('{')))) << r.out;
      ASSERT_TRUE(j.contains("crossval")) << what << ": " << r.out;
      double got = j["crossval"]["rel_error"];
      EXPECT_LT(std::abs(got - want.crossval->rel_error), kRelTol * want.crossval->rel_error)
          << what << ": cv error " << got << ", serial " << want.crossval->rel_error;
      EXPECT_EQ(j["crossval"]["folds"], want.crossval->folds) << what;
      EXPECT_EQ(j["crossval"]["evaluated"], want.crossval->evaluated) << what;
      EXPECT_EQ(j["kernel"], want.kernel_cells) << what;
      EXPECT_EQ(j["resolution"], nlohmann::json({want.nx, want.ny, want.nz})) << what;
      if (want.choice) {
        ASSERT_TRUE(j.contains("choice")) << what;
        EXPECT_EQ(j["choice"]["buckets_used"], want.choice->buckets_used) << what;
        ASSERT_EQ(j["choice"]["trials"].size(), want.choice->trials.size()) << what;
        for (size_t i = 0; i < want.choice->trials.size(); ++i) {
          double e = j["choice"]["trials"][i]["cv_error"], w = want.choice->trials[i].cv_error;
          EXPECT_LT(std::abs(e - w), kRelTol * w) << what << ", trial " << i;
        }
      }
      double dg = expect_same(grid, out, what), de = expect_same(ev, err, what + " (error volume)", true);
      std::printf(
          "[ilf] mpi cv: %s (kernel %g, %dx%dx%d): cv error %.9f, relative difference to serial %.1e; grid %.1e, "
          "error volume %.1e (worst value); %.1f s\n",
          what.c_str(), want.kernel_cells, want.nx, want.ny, want.nz, want.crossval->rel_error,
          std::abs(got - want.crossval->rel_error) / want.crossval->rel_error, dg, de, seconds);
    }
  }
}

TEST_F(IlfMpi, BadFrameFailsOnceOrIsSkippedOnEveryRank) {
  // Probe 40's frame is garbage: rank 2 of 3 reads it.
  std::string frame = read_sequence(manifest_).probes[40].image;
  std::ofstream(frame, std::ios::binary | std::ios::trunc) << "not an image";
  std::string out = dir_ + "/g.shgrid";
  auto r = mpirun(3, fmt::format("{} --grid 6 --out {}", manifest_, out));
  EXPECT_NE(r.status, 0) << r.out;
  EXPECT_NE(r.status, 124) << "the job hung:\n" << r.out;
  EXPECT_NE(r.out.find("probe 40"), std::string::npos) << r.out;
  // The serial build's message, word for word.
  auto s = run(fmt::format("{} --quiet ilf build {} --grid 6 --out {}", iblkit_command(), manifest_, out));
  EXPECT_NE(s.status, 0);
  std::string line = s.out.substr(0, s.out.find('\n'));
  EXPECT_NE(line.find("skip_bad"), std::string::npos) << line;
  EXPECT_NE(r.out.find(line), std::string::npos) << "serial: " << line << "\nmpi: " << r.out;
  size_t first = r.out.find("iblkit: error:");
  EXPECT_NE(first, std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("iblkit: error:", first + 1), std::string::npos) << "the error is printed more than once:\n"
                                                                        << r.out;
  EXPECT_FALSE(fs::exists(out));
  // --skip-bad: the serial build's grid without probe 40.
  BuildDesc bd;
  bd.nx = bd.ny = bd.nz = 6;
  SHGrid want = serial(bd, true);
  r = mpirun(3, fmt::format("{} --grid 6 --kernel 3 --cv-folds 0 --out {} --skip-bad", manifest_, out));
  ASSERT_EQ(r.status, 0) << r.out;
  expect_same(want, out, "--skip-bad, 3 ranks");
}

TEST_F(IlfMpi, ReRunReusesTheBucketsAndGivesTheSameGrid) {
  std::string args = fmt::format("{} --grid 6 --buckets {}/b --json", manifest_, dir_);
  auto a = mpirun(2, args + " --out " + dir_ + "/a.shgrid");
  ASSERT_EQ(a.status, 0) << a.out;
  EXPECT_NE(a.out.find("\"buckets_reused\": false"), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("\"ranks\": 2"), std::string::npos) << a.out;
  auto b = mpirun(2, args + " --out " + dir_ + "/b.shgrid");
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_NE(b.out.find("\"buckets_reused\": true"), std::string::npos) << b.out;
  std::ifstream fa(dir_ + "/a.shgrid", std::ios::binary), fb(dir_ + "/b.shgrid", std::ios::binary);
  std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_TRUE(sa == sb) << "the re-run's grid differs";
}

}  // namespace
}  // namespace ibl::ilf
