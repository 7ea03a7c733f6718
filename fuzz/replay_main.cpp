// Replays inputs through the fuzz harnesses without libFuzzer (any compiler): every file given, or
// every file under a folder given, is fed to the harness's LLVMFuzzerTestOneInput. Success or a clean
// error (the harness's policy, fuzz_common.h) passes; a crash or an escaping exception fails the run.
//   iblkit_fuzz_replay HARNESS FILE_OR_DIR…
// Each harness source is compiled here with LLVMFuzzerTestOneInput renamed to iblkit_fuzz_<name>; the
// generated header lists them.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_replay_harnesses.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: iblkit_fuzz_replay HARNESS FILE_OR_DIR…\nharnesses:");
    for (const auto& h : kHarnesses) std::fprintf(stderr, " %s", h.name);
    std::fprintf(stderr, "\n");
    return 2;
  }
  const Harness* h = nullptr;
  for (const auto& c : kHarnesses)
    if (std::string(c.name) == argv[1]) h = &c;
  if (!h) {
    std::fprintf(stderr, "iblkit_fuzz_replay: unknown harness '%s'\n", argv[1]);
    return 2;
  }
  std::vector<fs::path> files;
  for (int i = 2; i < argc; ++i) {
    fs::path p = argv[i];
    if (fs::is_directory(p)) {
      for (const auto& e : fs::recursive_directory_iterator(p))
        if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
    } else if (fs::exists(p)) {
      files.push_back(p);
    } else {
      std::fprintf(stderr, "iblkit_fuzz_replay: %s: no such file or folder\n", p.c_str());
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "replay %s: %s (%zu bytes)\n", h->name, f.c_str(), bytes.size());
    h->fn(bytes.data(), bytes.size());
  }
  std::printf("iblkit_fuzz_replay %s: %zu inputs, all ended in success or a clean error\n", h->name, files.size());
  return 0;
}
