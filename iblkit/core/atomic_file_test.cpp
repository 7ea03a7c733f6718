#include "iblkit/core/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("iblkit_atomic_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The names in a folder, sorted.
std::vector<std::string> listing(const fs::path& d) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(d)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(AtomicFile, TempBesideTheOutputKeepsTheExtension) {
  auto d = fresh_dir("names");
  AtomicFile a((d / "probe.exr").string()), b((d / "probe.exr").string());
  fs::path ta(a.temp_path());
  EXPECT_EQ(ta.parent_path(), d);
  EXPECT_EQ(ta.extension(), ".exr");
  EXPECT_EQ(ta.filename().string().rfind("probe.tmp-" + std::to_string(::getpid()) + "-", 0), 0u) << ta;
  EXPECT_NE(a.temp_path(), b.temp_path());
  EXPECT_TRUE(listing(d).empty());  // nothing is created before the writer writes
  fs::remove_all(d);
}

TEST(AtomicFile, CommitReplacesAndAbandonLeavesThePreviousFile) {
  auto d = fresh_dir("commit");
  std::string out = (d / "a.json").string();
  write_file_atomically(out, "first\n");
  EXPECT_EQ(slurp(out), "first\n");
  write_file_atomically(out, "second\n");
  EXPECT_EQ(slurp(out), "second\n");
  {
    AtomicFile f(out);
    std::ofstream(f.temp_path()) << "half of a thi";
    // a writer that fails here throws, and the destructor removes the temporary file
  }
  EXPECT_EQ(slurp(out), "second\n");
  EXPECT_EQ(listing(d), std::vector<std::string>{"a.json"});
  fs::remove_all(d);
}

TEST(AtomicFile, FailuresNameTheFileAndLeaveNothing) {
  auto d = fresh_dir("fail");
  std::string missing = (d / "no_such_folder" / "x.json").string();
  try {
    write_file_atomically(missing, "x");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Io);
    EXPECT_NE(std::string(e.what()).find(missing + ": cannot write"), std::string::npos) << e.what();
  }
  // A folder where the file should go: the rename fails, and the temporary file goes.
  fs::create_directories(d / "taken.json");
  EXPECT_THROW(write_file_atomically((d / "taken.json").string(), "x"), Error);
  EXPECT_EQ(listing(d), std::vector<std::string>{"taken.json"});
  EXPECT_TRUE(fs::is_empty(d / "taken.json"));
  fs::remove_all(d);
}

TEST(AtomicFile, LinksAndDevices) {
  auto d = fresh_dir("links");
  write_file_atomically((d / "real.txt").string(), "old");
  fs::create_symlink("real.txt", d / "link.txt");
  write_file_atomically((d / "link.txt").string(), "new");
  EXPECT_TRUE(fs::is_symlink(d / "link.txt"));  // the link stays a link; its target is replaced
  EXPECT_EQ(slurp(d / "real.txt"), "new");
  EXPECT_EQ(listing(d), (std::vector<std::string>{"link.txt", "real.txt"}));
  // A device is written in place, never replaced by a regular file.
  AtomicFile null("/dev/null");
  EXPECT_EQ(null.temp_path(), "/dev/null");
  write_file_atomically("/dev/null", "discarded");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  fs::remove_all(d);
}

TEST(AtomicFile, JsonRoundTrip) {
  auto d = fresh_dir("json");
  std::string p = (d / "s.json").string();
  nlohmann::json j = {{"format", "iblkit.test/1"}, {"values", {1, 2, 3}}};
  write_json_file(p, j);
  EXPECT_EQ(read_json_file(p), j);
  EXPECT_EQ(slurp(p), j.dump(1) + "\n");
  fs::remove_all(d);
}

// Killed while writing: the handler of remove_temp_files_on_signals() removes the temporary file,
// the process still dies of SIGTERM, and the previous output is intact.
TEST(AtomicFileDeathTest, SignalRemovesLiveTempFiles) {
  // The default ("fast") style forks, so the child writes into the folder this process checks.
  auto d = fresh_dir("signal");
  std::string out = (d / "grid.shgrid").string();
  write_file_atomically(out, "previous");
  auto killed_while_writing = [&] {
    remove_temp_files_on_signals();
    AtomicFile a(out);
    AtomicFile b((d / "other.exr").string());
    std::ofstream(a.temp_path()) << "partial";
    std::ofstream(b.temp_path()) << "partial";
    ::raise(SIGTERM);
    std::exit(0);  // not reached
  };
  EXPECT_EXIT(killed_while_writing(),
      testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(listing(d), std::vector<std::string>{"grid.shgrid"});
  EXPECT_EQ(slurp(out), "previous");
  fs::remove_all(d);
}

}  // namespace
}  // namespace ibl
