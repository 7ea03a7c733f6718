// libFuzzer harness: iblkit.lights/1 light sets (lights::read_lights).
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay lights FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/lights/light_set.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  return ibl::fuzz::guarded([&] {
    auto set = ibl::lights::read_lights(path);
    ibl::lights::total_irradiance(set);
  });
}
