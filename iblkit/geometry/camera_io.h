// iblkit.camera/1: the one pinhole camera (Camera) as a JSON file (docs/formats.md):
//   {"format":"iblkit.camera/1","eye":[x,y,z],"target":[x,y,z],"up":[0,1,0],"fov_y_deg":40}
// optionally with "width" and "height" (pixels); the frame's size is otherwise the photograph's; optionally
// with a photograph's lens: "intrinsics": {"fx","fy","cx","cy"} (pixels, continuous coordinates; needs
// width and height; fov_y_deg may then be omitted) and "distortion": [k1, k2, p1, p2, k3] (OpenCV's).
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "iblkit/geometry/camera.h"

namespace ibl::geometry {

// Checks eye, target and up (finite, |·| ≤ 1e6 m, eye ≠ target, up not parallel to the view),
// fov_y_deg in (0, 179), the frame size (1..16384) and the lens (require_lens); throws ibl::Error naming `what` and the
// field.
void validate_camera(const Camera& cam, const std::string& what);

// Reads a camera file. Width and height come from the file when it has them, else stay 0.
Camera read_camera(const std::string& path);
void write_camera(const std::string& path, const Camera& cam, bool with_size = true);
// A camera with intrinsics is always written with its size (its intrinsics are pixels of that frame),
// and with the fov_y_deg it was given.
nlohmann::json camera_to_json(const Camera& cam, bool with_size = true);
Camera camera_from_json(const nlohmann::json& j, const std::string& what);

}  // namespace ibl::geometry
