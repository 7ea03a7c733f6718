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
#include <utility>
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
//
// A ChArUco board, `charuco:SQXxSQY:SQUARE_M:MARKER_M[:DICT]`, counts squares as OpenCV and the printing tools do
// (SQX across the page, SQY down it): OpenCV's CharucoBoard as cv::aruco::CharucoBoard::draw prints it, ArUco
// markers MARKER_M wide from dictionary DICT (4x4_50 by default; 4x4, 5x5, 6x6, 7x7 with 50, 100, 250 or 1000
// markers) in its light squares. Its inner corners are cols = SQX − 1 by rows = SQY − 1, placed as a checker's seen
// from the front: u across the page (left to right), v up the page, the origin the bottom-left inner corner as
// printed; corner (a, b) is OpenCV's ChArUco corner id (rows − 1 − b)·cols + a. Each corner is known by its markers,
// so a board partly hidden (by the object, its shadow, the frame's edge) still gives the corners it shows.
struct Board {
  int cols = 0, rows = 0;
  double square = 0;
  Vec3 origin{0, 0, 0}, u{1, 0, 0}, v{0, 0, -1};
  bool charuco = false;
  double marker = 0;            // ChArUco: the markers' side, metres
  int dictionary = 0;           // ChArUco: OpenCV's cv::aruco::PREDEFINED_DICTIONARY_NAME
  std::string dictionary_name;  // ChArUco: as the spec names it ("4x4_50")
  // Corner (a, b), a < cols along u, b < rows along v, at origin + square (a u + b v); index b·cols + a.
  Vec3 corner(int a, int b) const { return origin + (u * a + v * b) * square; }
  std::vector<Vec3> corners() const;
  // In words, for messages: "7x4-corner chessboard", "5x4-square ChArUco board".
  std::string describe() const;
  // What to check when find_board finds nothing.
  std::string find_hint() const;
};
// Parses the spec (`option` names it in messages: "--board") and checks it. A checker: 3..100 corners each way,
// COLS ≠ ROWS and COLS + ROWS odd (so that the colours tell the board's orientation), 0 < SQUARE_M ≤ 10. A ChArUco
// board: 3..100 squares each way, 0 < MARKER_M < SQUARE_M ≤ 10, and a dictionary holding its SQX·SQY/2 markers.
Board parse_board(const std::string& spec, const std::string& option);
// The ChArUco board as printed (cv::aruco::CharucoBoard::draw, no margin): one channel, 1 light, 0 dark,
// `px_per_square` pixels a square, row 0 the page's top (the far end along v).
Image draw_charuco(const Board& board, int px_per_square);
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
  int dropped = 0;        // solve_board_camera: corners left out as misread
};

// The pose of a width × height photograph from ≥ 6 correspondences: `lens` carries the frame size and, with
// LensMode::Fixed, the lens. Coplanar points are solved with SOLVEPNP_IPPE, others with SOLVEPNP_ITERATIVE
// (from EPnP), SolveFocal by a scan of vertical fields of view 10°..120° refined by calibrateCamera.
// Throws (ErrorKind::Value) when the result has points behind the camera.
Solved solve_camera(const std::vector<Correspondence>& pts, const geometry::Camera& lens, LensMode mode);

// solve_camera for a board's corners (find_board). A ChArUco corner read from a marker half in a pool of light can
// land pixels off while its neighbours are right: after the first solve, corners whose reprojection error exceeds
// max(1 px, 3 × the median) are dropped and the pose solved again, up to three rounds, while at least
// kMinCorrespondences stay
// (Solved::dropped counts them). A checker's corners are found together or not at all: solved as they are.
Solved solve_board_camera(const Board& board, std::vector<Correspondence> pts, const geometry::Camera& lens,
                          LensMode mode);

// The board's inner corners found in a photograph (findChessboardCorners + cornerSubPix), paired with their
// world positions; nothing when the board is not found. Throws when it is seen from behind (u × v away
// from the camera). A ChArUco board: the corners its detected markers name (cv::aruco::detectMarkers +
// interpolateCornersCharuco), at least kMinCorrespondences of them, else nothing.
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
  // ChArUco (null when OpenCV was found without its aruco module, libopencv-contrib-dev): corner ids and pixels;
  // the board drawn, 0..1.
  std::vector<std::pair<int, Vec2>> (*find_charuco)(const Image& grey, const Board& board) = nullptr;
  Image (*draw_charuco)(const Board& board, int px_per_square) = nullptr;
};
extern plugin::Provided<CvSolver> cv_solver;
}  // namespace detail

}  // namespace ibl::capture
