// libFuzzer harness: iblkit.sh/1 SH coefficient files (sh::read_coeffs, i.e. sh::coeffs_from_json and its checks).
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay sh FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/sh/coeffs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  return ibl::fuzz::guarded([&] {
    auto c = ibl::sh::read_coeffs(path);
    c.evaluate({0, 0, 1});
  });
}
