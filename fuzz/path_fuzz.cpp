// libFuzzer harness: iblkit.path/1 path files and bare point arrays (fusion::read_path).
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay path FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/fusion/local_lights.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  return ibl::fuzz::guarded([&] { ibl::fusion::read_path(path); });
}
