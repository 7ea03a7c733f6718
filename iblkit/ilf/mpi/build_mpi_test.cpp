// The distributed ILF build against the serial one (issue 18): `mpirun --oversubscribe -np N iblkit
// ilf build …` for N = 1, 2, 3 gives the serial build's coefficients to float rounding, fails on a bad
// frame with the serial build's message once (or skips it with --skip-bad) without hanging, and a
// re-run reuses the buckets. Runs the iblkit command beside this test binary under mpirun; skips
// where mpirun is absent. Open MPI refuses root unless told; the allowance goes to mpirun's own
// environment only.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

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
  return run(fmt::format("timeout {} env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
                         "mpirun --oversubscribe -np {} {} --quiet ilf build {}",
                         kTimeout, ranks, iblkit_command(), args));
}

class IlfMpi : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_mpirun()) GTEST_SKIP() << "mpirun is absent (install openmpi-bin): the distributed build is not tested";
    if (iblkit_command().empty()) GTEST_SKIP() << "no iblkit command beside the test binary";
    dir_ = (fs::temp_directory_path() / fmt::format("iblkit_mpi_{}_{}", ::testing::UnitTest::GetInstance()->current_test_info()->name(), ::getpid())).string();
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
  void expect_same(const SHGrid& a, const std::string& path, const std::string& what) {
    SHGrid b = read_shgrid(path);
    ASSERT_EQ(a.data().size(), b.data().size()) << what;
    int bad = 0;
    double worst = 0;
    for (size_t i = 0; i < a.data().size(); ++i) {
      double x = a.data()[i], y = b.data()[i], d = std::abs(x - y);
      if (d > kRelTol * std::abs(x)) ++bad;
      if (x != 0) worst = std::max(worst, d / std::abs(x));
    }
    EXPECT_EQ(bad, 0) << what << ": " << bad << " of " << a.data().size() << " coefficients differ by more than 1e-6 (worst " << worst << ")";
  }
  std::string dir_, manifest_;
};

TEST_F(IlfMpi, SameGridAsSerialOnOneTwoThreeRanks) {
  struct Case { std::string args; BuildDesc bd; };
  BuildDesc pixel;
  pixel.nx = pixel.ny = pixel.nz = 6;
  pixel.buckets.octahedral = 0;
  BuildDesc oct = pixel;
  oct.buckets.octahedral = 6;
  oct.project.repair = Repair::PullPush;
  oct.bands = 3;
  BuildDesc sub = pixel;
  sub.subsample = SubsampleDesc{0.5, 0.5};
  std::vector<Case> cases = {{"--grid 6 --directions pixel", pixel},
                             {"--grid 6 --directions 6 --repair pullpush --bands 3", oct},
                             {"--grid 6 --directions pixel --subsample 0.5 --subsample-distance 0.5", sub}};
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
  EXPECT_EQ(r.out.find("iblkit: error:", first + 1), std::string::npos) << "the error is printed more than once:\n" << r.out;
  EXPECT_FALSE(fs::exists(out));
  // --skip-bad: the serial build's grid without probe 40.
  BuildDesc bd;
  bd.nx = bd.ny = bd.nz = 6;
  SHGrid want = serial(bd, true);
  r = mpirun(3, fmt::format("{} --grid 6 --out {} --skip-bad", manifest_, out));
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
