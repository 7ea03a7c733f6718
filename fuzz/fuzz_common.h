// Shared by the libFuzzer harnesses (fuzz/<name>_fuzz.cpp) and their replay executable.
//
// Policy: a reader may end in success or ibl::Error (the library's one exception type). A crash, a
// sanitizer report, a leak, an allocation past libFuzzer's limit or any other exception escaping the
// reader is a finding. nlohmann::json exceptions that escape a reader are the raw-message defect of
// the error rule ("Messages are one line that names the file…"), not a memory-safety fault: they count as
// clean unless IBLKIT_FUZZ_STRICT=1 is set, so that fuzzing goes on past them.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"

namespace ibl::fuzz {

// A folder of this process's own under the temp dir, removed at exit.
inline const std::filesystem::path& work_dir() {
  // Never destroyed (the exit handler that removes the folder runs after static destructors).
  static const std::filesystem::path* dir = [] {
    auto* d = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                        ("iblkit-fuzz-" + std::to_string(::getpid())));
    std::filesystem::create_directories(*d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(work_dir(), ec);
    });
    return d;
  }();
  return *dir;
}

// Writes bytes to work_dir()/name and returns the path (the same file every call: readers that take a
// path get the input this way).
inline std::string write_input(const std::string& name, const uint8_t* data, size_t size) {
  auto p = work_dir() / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  out.close();
  return p.string();
}

inline void write_text(const std::string& name, std::string_view text) {
  std::ofstream out(work_dir() / name, std::ios::binary | std::ios::trunc);
  out.write(text.data(), std::streamsize(text.size()));
}

inline bool env_is_1(const char* name) {
  const char* e = std::getenv(name);
  return e && std::string(e) == "1";
}

inline bool strict() {
  static const bool s = env_is_1("IBLKIT_FUZZ_STRICT");
  return s;
}

// IBLKIT_FUZZ_VERBOSE=1: print every clean error (to see what a seed or a crash file ends in).
inline bool verbose() {
  static const bool v = env_is_1("IBLKIT_FUZZ_VERBOSE");
  return v;
}

// Runs fn under the policy above; returns 0 (libFuzzer's "keep going").
template <typename Fn>
int guarded(Fn&& fn) {
  try {
    fn();
  } catch (const ibl::Error& e) {
    if (verbose()) std::fprintf(stderr, "  clean error: %s\n", e.what());
  } catch (const nlohmann::json::exception& e) {
    if (verbose()) std::fprintf(stderr, "  json exception (raw message): %s\n", e.what());
    if (strict()) {
      std::fprintf(stderr, "iblkit-fuzz: nlohmann::json exception escaped the reader: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}

// A tiny lat-long RGB .pfm (4x2) and a unit cube as OBJ (inward-facing: a room to stand in), written
// once as support files for manifests that name other files.
inline void write_support_files() {
  static bool done = false;
  if (done) return;
  done = true;
  std::string pfm = "PF\n4 2\n-1.0\n";
  for (int i = 0; i < 8; ++i) {
    float v[3] = {0.5f + 0.1f * float(i), 0.25f, 1.0f};
    pfm.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  write_text("probe.pfm", pfm);
  write_text("probe_depth.pfm", [] {
    std::string s = "Pf\n4 2\n-1.0\n";
    for (int i = 0; i < 8; ++i) {
      float v = 1.0f;
      s.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    return s;
  }());
  write_text("room.obj",
             "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
             "f 1 2 3\nf 1 3 4\nf 5 8 7\nf 5 7 6\nf 1 5 6\nf 1 6 2\nf 4 3 7\nf 4 7 8\nf 1 4 8\nf 1 8 5\n"
             "f 2 6 7\nf 2 7 3\n");
}

}  // namespace ibl::fuzz
