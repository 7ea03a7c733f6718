// The camera of a photograph (docs/camera.md): its pose, and optionally its intrinsics, from pixel ↔ world
// correspondences (iblkit.points/1 files, or a chessboard's corners found in the photograph), and a lens
// calibrated from several photographs of a board. OpenCV (calib3d: solvePnP, calibrateCamera,
// findChessboardCorners) does the solving; it sits in the "cv" plugin (core/plugin.h, libiblkit_cv.so,
// capture/camera_cv.cpp), loaded the first time one of these needs it. Everything else here (files,
// boards, checks, the reprojection error, which is measured with geometry::Camera::project) is OpenCV-free.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "iblkit/core/image.h"
#include "iblkit/core/plugin.h"
#include "iblkit/core/vec.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/io/photo.h"

namespace ibl::capture {

// One pixel ↔ world pair: the pixel in the continuous coordinates of geometry::Camera (the frame spans
// [0, W] × [0, H], pixel i's centre at i + ½), the world point in metres.
struct Correspondence {
  Vec2 pixel;
  Vec3 world;
};

inline constexpr int kMinCorrespondences = 6;

// iblkit.points/1: {"format":"iblkit.points/1","points":[{"pixel":[u,v],"world":[x,y,z]},…]}
// (docs/formats.md). Refuses fewer than kMinCorrespondences points and non-finite or out-of-range values,
// naming the file and the point.
std::vector<Correspondence> read_points(const std::string& path);
std::vector<Correspondence> points_from_json(const nlohmann::json& j, const std::string& what);
nlohmann::json points_to_json(const std::vector<Correspondence>& pts);

// A planar chessboard and where it lies: `checker:COLSxROWS:SQUARE_M` counts inner corners (OpenCV's
// pattern size: a board of (COLS + 1) × (ROWS + 1) squares), with the first inner corner at `origin`, the
// corners of a row along `u` (column index), the rows along `v`, SQUARE_M metres apart. The square
// between the first four inner corners is dark; u × v points out of the printed face, towards the camera.
struct Board {
  int cols = 0, rows = 0;
  double square = 0;
  Vec3 origin{0, 0, 0}, u{1, 0, 0}, v{0, 0, -1};
  // Corner (a, b), a < cols along u, b < rows along v, at origin + square (a u + b v); index b·cols + a.
  Vec3 corner(int a, int b) const { return origin + (u * a + v * b) * square; }
  std::vector<Vec3> corners() const;
};
// Parses the spec (`option` names it in messages: "--board") and checks it: 3..100 corners each way, COLS ≠
// ROWS and COLS + ROWS odd (so that the colours tell the board's orientation), 0 < SQUARE_M ≤ 10.
Board parse_board(const std::string& spec, const std::string& option);
// Sets origin and axes (u, v normalised, v made orthogonal to u; they must not be parallel).
void place_board(Board& b, Vec3 origin, Vec3 u, Vec3 v, const std::string& option);

// How the lens is treated while the pose is solved.
enum class LensMode {
  Fixed,      // the given camera's lens (its fov pinhole or its intrinsics and distortion) is kept
  SolveFocal  // one focal length (fx = fy) solved with the pose; centred principal point, no distortion
};

struct Reprojection {
  double rms_px = 0, max_px = 0;
  int worst = -1;  // index of the point with the largest error
  int behind = 0;  // points on or behind the eye's plane (they do not project)
};
// The reprojection error of the points through `cam` (geometry::Camera::project).
Reprojection reprojection(const geometry::Camera& cam, const std::vector<Correspondence>& pts);

struct Solved {
  geometry::Camera camera;  // eye, target (the points' centroid's depth along the view), up, lens, frame
  Reprojection error;
  bool coplanar = false;  // the world points lie on a plane (solved with IPPE)
};

// The pose of a width × height photograph from ≥ 6 correspondences: `lens` carries the frame size and, with
// LensMode::Fixed, the lens. Coplanar points are solved with SOLVEPNP_IPPE, others with SOLVEPNP_ITERATIVE
// (from EPnP), SolveFocal by a scan of vertical fields of view 10°..120° refined by calibrateCamera.
// Throws (ErrorKind::Value) when the result has points behind the camera.
Solved solve_camera(const std::vector<Correspondence>& pts, const geometry::Camera& lens, LensMode mode);

// The board's inner corners found in a photograph (findChessboardCorners + cornerSubPix), paired with their
// world positions; nothing when the board is not found. Throws when it is seen from behind (u × v away
// from the camera).
std::optional<std::vector<Correspondence>> find_board(const Image& photo, const Board& board);

struct Calibrated {
  geometry::Camera camera;  // intrinsics and distortion; the pose of the first photograph's board
  double rms_px = 0;        // calibrateCamera's RMS reprojection error over all photographs
  std::vector<double> per_view_rms_px;
  // calibrateCamera's standard deviations of fx, fy, cx, cy, k1, k2, p1, p2, k3: how well the photographs pin
  // the lens down (views alike, or the board always in the middle, leave the distortion free to wander).
  std::array<double, 9> std_dev{};
  // What the standard deviations say, in words: "k2 = −6.2 ± 3.1 (the photographs do not constrain it) …";
  // empty when every parameter is known to 1 % of the focal length, 0.05 in k1/k2/k3 and 0.005 in p1/p2.
  std::vector<std::string> warnings;
};
// A lens (fx, fy, cx, cy, k1 k2 p1 p2 k3) from the board's corners in several photographs of one size
// (each a list from find_board); at least 3.
Calibrated calibrate_camera(const std::vector<std::vector<Correspondence>>& views, int width, int height);

// The lens a photograph's Exif states, as an undistorted pinhole with the principal point at the centre (a
// prior: `camera solve` keeps it fixed while it solves the pose): the focal length FocalLength (mm) over the
// sensor's pixel pitch (FocalPlaneXResolution / FocalPlaneYResolution per FocalPlaneResolutionUnit: inch, cm
// or mm), else FocalLengthIn35mmFilm over the 36 × 24 mm frame's diagonal (whole millimetres: ±0.5 mm, a
// percent or two of the field of view). Nothing when the file states neither.
struct ExifLens {
  double fov_y_deg = 0;
  std::string source;  // in words: "Exif FocalLength 24 mm, focal plane 640 px / 3.6 cm"
};
std::optional<ExifLens> lens_from_exif(const io::PhotoMeta& meta, int width, int height);
// The Exif attributes that state `fov_y_deg` for a width × height frame of a sensor `sensor_width_mm` wide (what
// the lab writes; lens_from_exif reads them back).
std::vector<io::PhotoAttribute> exif_lens_attributes(double fov_y_deg, int width, int height,
                                                     double sensor_width_mm = 36);

namespace detail {
// What the "cv" plugin provides (capture/camera_cv.cpp).
struct CvSolver {
  Solved (*solve)(const std::vector<Correspondence>& pts, const geometry::Camera& lens, LensMode mode);
  std::optional<std::vector<Vec2>> (*find_chessboard)(const Image& grey, int cols, int rows);
  Calibrated (*calibrate)(const std::vector<std::vector<Correspondence>>& views, int width, int height);
};
extern plugin::Provided<CvSolver> cv_solver;
}  // namespace detail

}  // namespace ibl::capture
