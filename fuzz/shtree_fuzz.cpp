// libFuzzer harness: .shtree adaptive SH grids (ilf::read_adaptive), then lookups at the volume's centre
// and corners and a resampling to a small dense grid.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay shtree FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/ilf/adaptive.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.shtree", data, size);
  return ibl::fuzz::guarded([&] {
    auto g = ibl::ilf::read_adaptive(path);
    const auto& v = g.grid().volume;
    g.coeffs_at(v.centre());
    g.coeffs_at(v.min);
    g.irradiance(v.max, {0, 1, 0});
    g.to_dense(3, 3, 3);
  });
}
