// libFuzzer harness: iblkit.probes/1 fusion probe sets (fusion::load_probe_set: manifest, proxy, probes, depth,
// prepare). Beside the input lie room.obj (a cube proxy), probe.pfm (4x2 lat-long) and probe_depth.pfm for the manifest
// to name; no depth cache is written. Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay:
// iblkit_fuzz_replay probes FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/fusion/probe_set.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibl::fuzz::write_support_files();
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  return ibl::fuzz::guarded([&] {
    ibl::fusion::LoadDesc d;
    d.use_cache = false;
    d.write_cache = false;
    auto set = ibl::fusion::load_probe_set(path, d);
    (void)set;
  });
}
