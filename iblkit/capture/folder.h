// A capture folder (iblkit.capture/1, docs/formats.md "Capture folders"): what a user brings back from a set —
// the backplate, the chrome ball's brackets from one or two sides, the board lying in the scene, the proxy
// measured with a tape — and what is to be inserted, in one manifest `capture.json`, so that one command
// (`iblkit composite --capture DIR`) goes from the photographs to the composite. `lab shoot --backplate`
// writes one, with the truth besides.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "iblkit/capture/ball.h"
#include "iblkit/capture/camera_solve.h"
#include "iblkit/core/vec.h"

namespace ibl::capture {

struct CaptureView {
  std::vector<std::string> frames;     // the bracket (paths as written in the manifest: relative to the folder)
  double angle_deg = 0;                // where this view's camera stood about +Y from view 0's
  std::optional<BallCircle> ball;      // the silhouette in pixels; absent: found (find_ball)
  double distance_radii = 0;           // camera to ball centre in ball radii; 0: from the silhouette and the lens
  double focal_mm = 0, sensor_mm = 0;  // the lens, for distance_from_lens when distance_radii is 0
};

struct CaptureFolder {
  std::string dir;        // the folder (paths below are relative to it unless absolute)
  std::string backplate;  // the photograph the object goes into
  std::string response;   // how its codes are linear: "" (the curve recovered from the ball's brackets, when
                          // they are 8- or 16-bit and from the same camera; else sRGB), "srgb", "linear", a file
  // The backplate's camera: a board seen in it, and its lens: an iblkit.camera/1 file with intrinsics
  // (`camera calibrate`'s), or a vertical field of view, or neither (the backplate's Exif, else the focal
  // length solved with the pose).
  std::string board_spec;  // "checker:COLSxROWS:SQUARE_M"
  Board board;             // placed (origin, axes)
  std::string lens;
  double fov_deg = 0;
  // The chrome ball: where it stood, its size, which way view 0's camera looked at it, its views.
  Vec3 ball_center;
  double ball_radius = 0;  // metres
  Vec3 facing{0, 0, 1};    // world direction from the ball to view 0's camera
  std::string fresnel = "chrome";
  std::optional<Vec3> reflectance;  // normal-incidence reflectance (default: the metal's)
  std::vector<CaptureView> views;
  // The local scene and what goes into it.
  std::string proxy;            // mesh file (world metres)
  std::string object = "blob";  // blob, sphere, or a mesh file
  double object_size = 0.3;     // largest extent, metres (0: a mesh file's own)
  Vec3 object_at{0, 0.15, 0};   // where the object's centre goes
  Vec3 albedo{0.7, 0.7, 0.7};
  // The lab's answers (absent in a user's folder): the backplate photographed with the object really there
  // (same camera, same exposure, same noise), its mask, and the exact camera.
  std::string truth, truth_mask, truth_camera;

  // `path` relative to the folder (absolute paths as they are).
  std::string at(const std::string& path) const;
};

// Reads DIR/capture.json (or the manifest file itself). Throws ibl::Error naming the file and the field.
CaptureFolder read_capture(const std::string& dir_or_manifest);
nlohmann::json capture_to_json(const CaptureFolder& c);

// The rotation that turns a probe made from view 0 (from-ball's frame: the camera on +Z, +Y up) into the world:
// columns X, Y, Z with Z = facing, X ⟂ +Y.
Mat3 ball_frame(Vec3 facing);

}  // namespace ibl::capture
