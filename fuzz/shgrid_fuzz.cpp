// libFuzzer harness: .shgrid SH grids (ilf::read_shgrid), then lookups at the volume's centre and corners.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay shgrid FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/ilf/shgrid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.shgrid", data, size);
  return ibl::fuzz::guarded([&] {
    auto g = ibl::ilf::read_shgrid(path);
    const auto& v = g.grid().volume;
    g.coeffs_at(v.centre());
    g.coeffs_at(v.min);
    g.irradiance(v.max, {0, 1, 0});
  });
}
