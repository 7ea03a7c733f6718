// libFuzzer harness: iblkit.camera/1 camera files (geometry::read_camera: `composite --camera`,
// `lab photograph --camera`).
// Build: make fuzz (clang-14, -fsanitize=fuzzer,address,undefined); replay: iblkit_fuzz_replay camera FILE…
#include "fuzz/fuzz_common.h"
#include "iblkit/geometry/camera_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = ibl::fuzz::write_input("cam.json", data, size);
  return ibl::fuzz::guarded([&] {
    auto cam = ibl::geometry::read_camera(path);
    // What a reader hands on is usable: the rays of the frame's corners are finite.
    volatile double sink = cam.ray_direction(0, 0).x + cam.ray_direction(cam.width, cam.height).z;
    (void)sink;
  });
}
