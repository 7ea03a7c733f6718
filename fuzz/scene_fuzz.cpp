// libFuzzer harness: iblkit.scene/1 lab scenes (lab::load_scene, built: meshes, textures, probes, Embree scene).
// Beside the input lie room.obj, probe.pfm and probe_depth.pfm for the scene to name.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay scene FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/lab/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibl::fuzz::write_support_files();
  std::string path = ibl::fuzz::write_input("input.json", data, size);
  return ibl::fuzz::guarded([&] { ibl::lab::load_scene(path, true); });
}
