// libFuzzer harness: iblkit.sequence/1 probe sequences (ilf::read_sequence, strict and skip_bad).
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay sequence FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/ilf/sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  ibl::fuzz::guarded([&] { ibl::ilf::read_sequence(path); });
  return ibl::fuzz::guarded([&] {
    ibl::ilf::SequenceReadDesc d;
    d.skip_bad = true;
    ibl::ilf::SequenceReport r;
    ibl::ilf::read_sequence(path, d, &r);
  });
}
