// libFuzzer harness: iblkit.nearfield/1 dataset manifests (nearfield::read_dataset and Dataset::validate).
// Beside the input lie probe.pfm (4x2 RGB) and probe_depth.pfm for the manifest to name as images.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay nearfield FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/nearfield/dataset.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibl::fuzz::write_support_files();
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  return ibl::fuzz::guarded([&] {
    auto ds = ibl::nearfield::read_dataset(path);
    ds.validate(path);
    if (ds.count() > 0) ds.measurement(0, 0);
  });
}
