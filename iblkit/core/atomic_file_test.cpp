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

TEST(AtomicFile, MessagesNameTheOutputNotTheTemporary) {
  auto d = fresh_dir("naming");
  AtomicFile f((d / "probe.exr").string());
  Error raw(ErrorKind::Io, f.temp_path() + ": cannot open; tried " + f.temp_path() + " twice");
  Error named = f.naming_path(raw);
  EXPECT_EQ(named.kind(), ErrorKind::Io);
  EXPECT_EQ(std::string(named.what()), f.path() + ": cannot open; tried " + f.path() + " twice");
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
  // A file where a folder of the output should be (a missing folder is made: make_output_folders).
  std::ofstream(d / "not_a_folder") << "x";
  std::string missing = (d / "not_a_folder" / "x.json").string();
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
  EXPECT_EQ(listing(d), (std::vector<std::string>{"not_a_folder", "taken.json"}));
  EXPECT_TRUE(fs::is_empty(d / "taken.json"));
  fs::remove_all(d);
}

TEST(AtomicFile, NeverReplacesAnInput) {
  auto d = fresh_dir("inputs");
  write_file_atomically((d / "in.txt").string(), "input");
  fs::create_hard_link(d / "in.txt", d / "same.txt");
  {
    OutputTransaction tx;
    note_input_file((d / "in.txt").string());
    EXPECT_THROW(write_file_atomically((d / "in.txt").string(), "x"), Error);
    EXPECT_THROW(write_file_atomically((d / "same.txt").string(), "x"), Error);  // the same inode
    write_file_atomically((d / "out.txt").string(), "1");
    note_input_file((d / "out.txt").string());  // written by the command itself: not an input
    write_file_atomically((d / "out.txt").string(), "2");
    tx.commit();
  }
  EXPECT_EQ(slurp(d / "in.txt"), "input");
  EXPECT_EQ(slurp(d / "out.txt"), "2");
  EXPECT_EQ(listing(d), (std::vector<std::string>{"in.txt", "out.txt", "same.txt"}));
  fs::remove_all(d);
}

TEST(AtomicFile, LinksAndDevices) {
  auto d = fresh_dir("links");
  write_file_atomically((d / "real.txt").string(), "old");
  fs::create_symlink("real.txt", d / "link.txt");
  write_file_atomically((d / "link.txt").string(), "new");
  // The link is replaced, never written through (a link planted in an output folder).
  EXPECT_FALSE(fs::is_symlink(d / "link.txt"));
  EXPECT_EQ(slurp(d / "link.txt"), "new");
  EXPECT_EQ(slurp(d / "real.txt"), "old");
  EXPECT_EQ(listing(d), (std::vector<std::string>{"link.txt", "real.txt"}));
  // A dangling link and a link to a folder are replaced too.
  fs::create_symlink("nowhere.txt", d / "dangling.txt");
  write_file_atomically((d / "dangling.txt").string(), "x");
  EXPECT_FALSE(fs::exists(d / "nowhere.txt"));
  EXPECT_EQ(slurp(d / "dangling.txt"), "x");
  // A link to /dev/null (as /dev/stdout links to a pipe or a terminal) is written in place.
  fs::create_symlink("/dev/null", d / "null.txt");
  write_file_atomically((d / "null.txt").string(), "discarded");
  EXPECT_TRUE(fs::is_symlink(d / "null.txt"));
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
  EXPECT_EXIT(killed_while_writing(), testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(listing(d), std::vector<std::string>{"grid.shgrid"});
  EXPECT_EQ(slurp(out), "previous");
  fs::remove_all(d);
}

TEST(OutputTransaction, FailurePutsBackReplacedFilesAndRemovesNewOnes) {
  auto d = fresh_dir("tx_fail");
  write_file_atomically((d / "l.json").string(), "old lights");
  {
    OutputTransaction tx;
    write_file_atomically((d / "l.json").string(), "new lights");
    write_file_atomically((d / "l.json").string(), "newer lights");  // twice: the first state comes back
    make_output_folders((d / "frames" / "deep").string());
    write_file_atomically((d / "frames" / "deep" / "f0.exr").string(), "frame");
    write_file_atomically((d / "made" / "x.gltf").string(), "gltf");  // AtomicFile makes the folder
    EXPECT_EQ(slurp(d / "l.json"), "newer lights");                   // in place at once: readable by the command
    EXPECT_EQ(tx.files(), 3u);
    // ... the command throws here: no commit
  }
  EXPECT_EQ(listing(d), std::vector<std::string>{"l.json"});
  EXPECT_EQ(slurp(d / "l.json"), "old lights");
  fs::remove_all(d);
}

TEST(OutputTransaction, CommitKeepsEverythingAndLeavesNoKeptCopies) {
  auto d = fresh_dir("tx_commit");
  write_file_atomically((d / "s.json").string(), "old");
  fs::create_directories(d / "frames");
  write_file_atomically((d / "frames" / "keep.exr").string(), "someone else's");
  {
    OutputTransaction tx;
    EXPECT_THROW(OutputTransaction second, Error);  // one at a time
    write_file_atomically((d / "s.json").string(), "new");
    write_file_atomically((d / "i.exr").string(), "map");
    make_output_folders((d / "frames").string());  // there already: not the transaction's
    tx.commit();
    EXPECT_THROW(tx.commit(), Error);
  }
  EXPECT_EQ(listing(d), (std::vector<std::string>{"frames", "i.exr", "s.json"}));
  EXPECT_EQ(slurp(d / "s.json"), "new");
  // A rollback leaves a folder that was there, and one that holds a file it did not write.
  {
    OutputTransaction tx;
    write_file_atomically((d / "frames" / "f1.exr").string(), "frame");
  }
  EXPECT_EQ(listing(d / "frames"), std::vector<std::string>{"keep.exr"});
  {
    OutputTransaction tx;
    write_file_atomically((d / "new" / "a.exr").string(), "a");
    std::ofstream(d / "new" / "user.txt") << "written meanwhile by someone else";
  }
  EXPECT_EQ(listing(d / "new"), std::vector<std::string>{"user.txt"});
  fs::remove_all(d);
}

TEST(OutputTransaction, FolderErrorsNameTheFolder) {
  auto d = fresh_dir("tx_folders");
  write_file_atomically((d / "file").string(), "x");
  try {
    make_output_folders((d / "file" / "sub").string());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is not a folder"), std::string::npos) << e.what();
  }
  try {
    write_file_atomically((d / "file" / "sub" / "o.json").string(), "x");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("o.json: cannot write"), std::string::npos) << e.what();
  }
  make_output_folders((d / "a" / "b" / "").string());  // a trailing separator
  EXPECT_TRUE(fs::is_directory(d / "a" / "b"));
  fs::remove_all(d);
}

TEST(OutputTransactionDeathTest, SignalRollsBack) {
  auto d = fresh_dir("tx_signal");
  write_file_atomically((d / "l.json").string(), "previous");
  auto killed_after_one_output = [&] {
    remove_temp_files_on_signals();
    OutputTransaction tx;
    write_file_atomically((d / "l.json").string(), "new");
    write_file_atomically((d / "cap" / "frames" / "f0.exr").string(), "frame");
    ::raise(SIGTERM);
    std::exit(0);  // not reached
  };
  EXPECT_EXIT(killed_after_one_output(), testing::KilledBySignal(SIGTERM), "");
  EXPECT_EQ(listing(d), std::vector<std::string>{"l.json"});
  EXPECT_EQ(slurp(d / "l.json"), "previous");
  fs::remove_all(d);
}

}  // namespace
}  // namespace ibl
