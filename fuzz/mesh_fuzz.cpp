// libFuzzer harness: OBJ and PLY meshes through the mesh loader (geometry::read_mesh, assimp). The extension
// follows the input: .ply when it starts with "ply", else .obj.
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay mesh FILE…
#include <cstring>
#include "fuzz/fuzz_common.h"

#include "iblkit/geometry/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bool ply = size >= 3 && std::memcmp(data, "ply", 3) == 0;
  std::string path = ibl::fuzz::write_input(ply ? "input.ply" : "input.obj", data, size);
  return ibl::fuzz::guarded([&] { ibl::geometry::read_mesh(path); });
}
