// libFuzzer harness: images through io/ (io::read_image, io::read_envmap), OpenImageIO's own checks first. The
// extension follows the input's magic bytes, as a user's file would carry it.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay image FILE…
#include <cstring>

#include "fuzz/fuzz_common.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"

static const char* extension(const uint8_t* d, size_t n) {
  auto starts = [&](const char* m) {
    size_t k = std::char_traits<char>::length(m);
    return n >= k && std::memcmp(d, m, k) == 0;
  };
  if (starts("v/1\x01")) return ".exr";
  if (starts("#?")) return ".hdr";
  if (starts("PF") || starts("Pf")) return ".pfm";
  if (starts("II*") || starts("MM\x00*")) return ".tif";
  if (starts("\x89PNG")) return ".png";
  if (starts("\xFF\xD8")) return ".jpg";
  return ".exr";
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input(std::string("input") + extension(data, size), data, size);
  ibl::fuzz::guarded([&] { ibl::io::read_image(path); });
  ibl::fuzz::guarded([&] {
    ibl::io::ReadDesc rd;
    rd.sanitize = true;
    rd.max_channels = 3;
    ibl::io::read_image(path, rd);
  });
  ibl::fuzz::guarded([&] {
    ibl::io::EnvReadDesc ed;
    ed.sanitize = true;
    auto env = ibl::io::read_envmap(path, ed);
    (void)env;
  });
  return 0;
}
