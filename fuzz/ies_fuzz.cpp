// libFuzzer harness: IES LM-63 photometric files (nearfield::read_ies), then intensities along a few directions.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay ies FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/nearfield/ies.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.ies", data, size);
  return ibl::fuzz::guarded([&] {
    auto p = ibl::nearfield::read_ies(path);
    for (ibl::Vec3 w : {ibl::Vec3{0, 0, 1}, ibl::Vec3{0, 0, -1}, ibl::Vec3{1, 0, 0}, ibl::Vec3{0.6, 0.8, 0}})
      p.intensity(w);
  });
}
