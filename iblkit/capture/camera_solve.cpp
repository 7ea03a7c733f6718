#include "iblkit/capture/camera_solve.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

namespace ibl::capture {

namespace detail {
constinit plugin::Provided<CvSolver> cv_solver{"cv", "OpenCV camera solver"};
}  // namespace detail

std::vector<Correspondence> points_from_json(const nlohmann::json& j, const std::string& what) {
  require_format(j, what, "iblkit.points/1");
  if (!j.contains("points") || !j["points"].is_array())
    fail(ErrorKind::Format, "{}: \"points\" (an array of {{\"pixel\": [u, v], \"world\": [x, y, z]}}) is missing",
         what);
  std::vector<Correspondence> out;
  for (size_t i = 0; i < j["points"].size(); ++i) {
    const auto& p = j["points"][i];
    auto numbers = [&](const char* key, size_t n) {
      if (!p.is_object() || !p.contains(key) || !p[key].is_array() || p[key].size() != n)
        fail(ErrorKind::Format, "{}: points[{}].{} must be an array of {} numbers", what, i, key, n);
      std::vector<double> v;
      for (const auto& x : p[key]) {
        if (!x.is_number())
          fail(ErrorKind::Format, "{}: points[{}].{} must be an array of {} numbers", what, i, key, n);
        v.push_back(x.get<double>());
      }
      return v;
    };
    auto px = numbers("pixel", 2);
    auto w = numbers("world", 3);
    Correspondence c{{px[0], px[1]}, {w[0], w[1], w[2]}};
    if (!std::isfinite(c.pixel.x) || !std::isfinite(c.pixel.y) || std::abs(c.pixel.x) > 1e6 ||
        std::abs(c.pixel.y) > 1e6)
      fail(ErrorKind::Value, "{}: points[{}].pixel ({}, {}) is not a finite pixel position", what, i, c.pixel.x,
           c.pixel.y);
    require_point(fmt::format("{}: points[{}].world", what, i), c.world);
    out.push_back(c);
  }
  if (out.size() < static_cast<size_t>(kMinCorrespondences))
    fail(ErrorKind::Value, "{}: {} points; a camera needs at least {} pixel ↔ world pairs", what, out.size(),
         kMinCorrespondences);
  return out;
}

std::vector<Correspondence> read_points(const std::string& path) {
  return points_from_json(read_json_file(path), path);
}

nlohmann::json points_to_json(const std::vector<Correspondence>& pts) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& p : pts)
    a.push_back({{"pixel", {p.pixel.x, p.pixel.y}}, {"world", {p.world.x, p.world.y, p.world.z}}});
  return {{"format", "iblkit.points/1"}, {"points", a}};
}

std::vector<Vec3> Board::corners() const {
  std::vector<Vec3> c;
  for (int b = 0; b < rows; ++b)
    for (int a = 0; a < cols; ++a) c.push_back(corner(a, b));
  return c;
}

std::string Board::describe() const {
  return charuco ? fmt::format("{}x{}-square ChArUco board", cols + 1, rows + 1)
                 : fmt::format("{}x{}-corner chessboard", cols, rows);
}

std::string Board::find_hint() const {
  return charuco ? fmt::format(
                       "fewer than {} of its corners: at least two markers about each must be readable, a few "
                       "pixels a marker bit",
                       kMinCorrespondences)
                 : "check the counts: inner corners; the whole board must be in the frame";
}

namespace {

// OpenCV's predefined dictionaries DICT_4X4_50 (0) … DICT_7X7_1000 (15): bits 4..7, 50/100/250/1000 markers.
int dictionary_id(const std::string& name, int* size) {
  static const int kSizes[4] = {50, 100, 250, 1000};
  for (int bits = 4; bits <= 7; ++bits)
    for (int k = 0; k < 4; ++k)
      if (name == fmt::format("{}x{}_{}", bits, bits, kSizes[k])) {
        *size = kSizes[k];
        return (bits - 4) * 4 + k;
      }
  return -1;
}

Board parse_charuco(const std::string& spec, const std::string& option) {
  Board b;
  b.charuco = true;
  int sx = 0, sy = 0, n = 0;
  char dict[32] = {0};
  const int got = std::sscanf(spec.c_str(), "charuco:%dx%d:%lf:%lf%n", &sx, &sy, &b.square, &b.marker, &n);
  std::string rest = got == 4 ? spec.substr(static_cast<size_t>(n)) : std::string("?");
  if (got == 4 && rest.size() > 1 && rest[0] == ':' && rest.size() < sizeof dict + 1) {
    std::copy(rest.begin() + 1, rest.end(), dict);
    rest.clear();
  }
  if (got != 4 || !rest.empty())
    fail(ErrorKind::Value,
         "{} {}: expected charuco:SQXxSQY:SQUARE_M:MARKER_M[:DICT] (squares, metres; DICT 4x4_50 by default), e.g. "
         "charuco:5x4:0.2:0.15",
         option, spec);
  b.dictionary_name = dict[0] ? dict : "4x4_50";
  int size = 0;
  b.dictionary = dictionary_id(b.dictionary_name, &size);
  if (b.dictionary < 0)
    fail(ErrorKind::Value, "{} {}: dictionary '{}': use NxN_M with N 4..7 and M 50, 100, 250 or 1000 (4x4_50)", option,
         spec, b.dictionary_name);
  if (sx < 3 || sy < 3 || sx > 100 || sy > 100)
    fail(ErrorKind::Value, "{} {}: {}x{} squares; each count must lie in 3..100", option, spec, sx, sy);
  if (!(b.square > 0 && b.square <= 10))
    fail(ErrorKind::Value, "{} {}: square size {} m must lie in (0, 10]", option, spec, b.square);
  if (!(b.marker > 0 && b.marker < b.square))
    fail(ErrorKind::Value, "{} {}: marker size {} m must be positive and smaller than the square ({} m)", option, spec,
         b.marker, b.square);
  if (sx * sy / 2 > size)
    fail(ErrorKind::Value, "{} {}: {} markers, but dictionary {} holds {}; name a larger one (e.g. :{}_1000)", option,
         spec, sx * sy / 2, b.dictionary_name, size, b.dictionary_name.substr(0, 3));
  b.cols = sx - 1;
  b.rows = sy - 1;
  return b;
}

const detail::CvSolver& aruco(const char* what) {
  const detail::CvSolver& cv = detail::cv_solver.get();
  if (!cv.find_charuco || !cv.draw_charuco)
    fail(ErrorKind::Value,
         "{}: this build's OpenCV has no aruco module (scripts/install-deps installs libopencv-contrib-dev); use a "
         "checker:COLSxROWS:SQUARE_M board",
         what);
  return cv;
}

}  // namespace

Image draw_charuco(const Board& board, int px_per_square) {
  if (!board.charuco) fail(ErrorKind::Internal, "draw_charuco: not a ChArUco board");
  if (px_per_square < 8 || px_per_square > 512)
    fail(ErrorKind::Value, "draw_charuco: {} pixels a square outside 8..512", px_per_square);
  return aruco("a ChArUco board").draw_charuco(board, px_per_square);
}

Board parse_board(const std::string& spec, const std::string& option) {
  if (spec.rfind("charuco:", 0) == 0) return parse_charuco(spec, option);
  Board b;
  int n = 0;
  char tail = 0;
  if (std::sscanf(spec.c_str(), "checker:%dx%d:%lf%n%c", &b.cols, &b.rows, &b.square, &n, &tail) != 3 ||
      n != static_cast<int>(spec.size()))
    fail(ErrorKind::Value,
         "{} {}: expected checker:COLSxROWS:SQUARE_M (inner corners, metres), e.g. checker:9x6:0.05, or "
         "charuco:SQXxSQY:SQUARE_M:MARKER_M[:DICT]",
         option, spec);
  if (b.cols < 3 || b.rows < 3 || b.cols > 100 || b.rows > 100)
    fail(ErrorKind::Value, "{} {}: {}x{} inner corners; each count must lie in 3..100", option, spec, b.cols, b.rows);
  if (b.cols == b.rows || (b.cols + b.rows) % 2 == 0)
    fail(ErrorKind::Value,
         "{} {}: a {}x{} board looks the same turned around; use one odd and one even count of inner corners "
         "(9x6, 7x4)",
         option, spec, b.cols, b.rows);
  if (!(b.square > 0 && b.square <= 10))
    fail(ErrorKind::Value, "{} {}: square size {} m must lie in (0, 10]", option, spec, b.square);
  return b;
}

void place_board(Board& b, Vec3 origin, Vec3 u, Vec3 v, const std::string& option) {
  require_point(option + " origin", origin);
  Vec3 un = require_direction(option + " u axis", u), vn = require_direction(option + " v axis", v);
  Vec3 vo = vn - un * dot(un, vn);
  if (length(vo) < 1e-6) fail(ErrorKind::Value, "{}: the u and v axes are parallel", option);
  b.origin = origin;
  b.u = un;
  b.v = normalize(vo);
}

Reprojection reprojection(const geometry::Camera& cam, const std::vector<Correspondence>& pts) {
  Reprojection r;
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    auto q = cam.project(pts[i].world);
    if (!q) {
      ++r.behind;
      continue;
    }
    double e = std::hypot(q->x - pts[i].pixel.x, q->y - pts[i].pixel.y);
    sum += e * e;
    ++n;
    if (e > r.max_px || r.worst < 0) r.max_px = e, r.worst = static_cast<int>(i);
  }
  r.rms_px = n ? std::sqrt(sum / n) : 0;
  return r;
}

Solved solve_camera(const std::vector<Correspondence>& pts, const geometry::Camera& lens, LensMode mode) {
  if (pts.size() < static_cast<size_t>(kMinCorrespondences))
    fail(ErrorKind::Value, "{} points; a camera needs at least {} pixel ↔ world pairs", pts.size(),
         kMinCorrespondences);
  for (const auto& p : pts) {
    require_point("world point", p.world);
    if (!std::isfinite(p.pixel.x) || !std::isfinite(p.pixel.y))
      fail(ErrorKind::Value, "pixel ({}, {}) is not finite", p.pixel.x, p.pixel.y);
  }
  if (lens.width < 1 || lens.height < 1) fail(ErrorKind::Value, "camera solve: the frame size is unknown");
  Solved s = detail::cv_solver.get().solve(pts, lens, mode);
  s.error = reprojection(s.camera, pts);
  if (s.error.behind)
    fail(ErrorKind::Value, "camera solve: {} of the {} points come out behind the solved camera", s.error.behind,
         pts.size());
  return s;
}

namespace {

// Mean grey over the middle of the quadrilateral of four image points.
double cell_grey(const Image& grey, Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  double sum = 0;
  int n = 0;
  for (double s : {0.3, 0.5, 0.7})
    for (double t : {0.3, 0.5, 0.7}) {
      Vec2 p = (a * ((1 - s) * (1 - t)) + b * (s * (1 - t)) + c * ((1 - s) * t) + d * (s * t));
      int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
      if (x < 0 || y < 0 || x >= grey.width() || y >= grey.height()) continue;
      sum += grey.at(x, y, 0);
      ++n;
    }
  return n ? sum / n : 0;
}

}  // namespace

std::optional<std::vector<Correspondence>> find_board(const Image& photo, const Board& board) {
  Image grey(photo.width(), photo.height(), 1);
  for (int y = 0; y < photo.height(); ++y)
    for (int x = 0; x < photo.width(); ++x) {
      const float* p = photo.pixel(x, y);
      grey.at(x, y, 0) = photo.channels() >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
    }
  if (board.charuco) {
    const auto ids = aruco(board.describe().c_str()).find_charuco(grey, board);
    if (static_cast<int>(ids.size()) < kMinCorrespondences) return std::nullopt;
    std::vector<Correspondence> out;
    for (const auto& [id, px] : ids) {
      if (id < 0 || id >= board.cols * board.rows) continue;
      out.push_back({px, board.corner(id % board.cols, board.rows - 1 - id / board.cols)});
    }
    return out;
  }
  auto found = detail::cv_solver.get().find_chessboard(grey, board.cols, board.rows);
  if (!found) return std::nullopt;
  const int C = board.cols, R = board.rows;
  std::vector<Vec2>& c = *found;  // OpenCV's order: row b, column a at b·C + a; pixels in continuous coordinates
  auto at = [&](int a, int b) { return c[static_cast<size_t>(b) * C + a]; };
  // Relabel (a, b) so that the board's axes have the handedness of a face seen from the front (u × v towards
  // the camera: in the image, x right and y down, the cross product of the u and v directions is negative)…
  Vec2 du = at(C - 1, 0) - at(0, 0), dv = at(0, R - 1) - at(0, 0);
  bool mirror = du.x * dv.y - du.y * dv.x > 0;
  std::vector<Vec2> m(c.size());
  for (int b = 0; b < R; ++b)
    for (int a = 0; a < C; ++a) m[static_cast<size_t>(b) * C + a] = at(mirror ? C - 1 - a : a, b);
  // …and so that the square between the first four corners is the dark one (COLS + ROWS is odd, so the
  // board turned by 180° puts a light square there).
  auto mt = [&](int a, int b) { return m[static_cast<size_t>(b) * C + a]; };
  double first = cell_grey(grey, mt(0, 0), mt(1, 0), mt(0, 1), mt(1, 1));
  double next = cell_grey(grey, mt(1, 0), mt(2, 0), mt(1, 1), mt(2, 1));
  bool turn = first > next;
  std::vector<Correspondence> out;
  for (int b = 0; b < R; ++b)
    for (int a = 0; a < C; ++a) {
      Vec2 px = turn ? mt(C - 1 - a, R - 1 - b) : mt(a, b);
      out.push_back({px, board.corner(a, b)});
    }
  return out;
}

Solved solve_board_camera(const Board& board, std::vector<Correspondence> pts, const geometry::Camera& lens,
                          LensMode mode) {
  Solved s = solve_camera(pts, lens, mode);
  if (!board.charuco) return s;
  int dropped = 0;
  for (int round = 0; round < 3; ++round) {
    std::vector<double> err;
    for (const auto& p : pts) {
      const auto q = s.camera.project(p.world);
      err.push_back(q ? std::hypot(q->x - p.pixel.x, q->y - p.pixel.y) : 1e300);
    }
    std::vector<double> sorted = err;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double limit = std::max(1.0, 3 * sorted[sorted.size() / 2]);
    std::vector<Correspondence> kept;
    for (size_t i = 0; i < pts.size(); ++i)
      if (err[i] <= limit) kept.push_back(pts[i]);
    if (kept.size() == pts.size() || static_cast<int>(kept.size()) < kMinCorrespondences) break;
    dropped += static_cast<int>(pts.size() - kept.size());
    pts.swap(kept);
    s = solve_camera(pts, lens, mode);
  }
  s.dropped = dropped;
  return s;
}

Calibrated calibrate_camera(const std::vector<std::vector<Correspondence>>& views, int width, int height) {
  if (views.size() < 3)
    fail(ErrorKind::Value, "camera calibrate: {} photographs; a lens needs at least 3", views.size());
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    fail(ErrorKind::Value, "camera calibrate: frame size {}x{} outside 1..16384", width, height);
  Calibrated c = detail::cv_solver.get().calibrate(views, width, height);
  geometry::require_lens(c.camera, "camera calibrate");
  return c;
}

namespace {

// An Exif attribute's value as OpenImageIO writes it out ("24", "24.5", a rational "49/2"); 0 when absent or not a
// positive finite number.
double exif_number(const io::PhotoMeta& meta, const std::string& name) {
  for (const io::PhotoAttribute& a : meta.attributes) {
    if (a.name != name) continue;
    double num = 0, den = 1;
    char slash = 0, tail = 0;
    const int n = std::sscanf(a.value.c_str(), "%lf%c%lf%c", &num, &slash, &den, &tail);
    if (n == 1 || (n == 3 && slash == '/')) {
      const double v = num / den;
      return std::isfinite(v) && v > 0 ? v : 0;
    }
    return 0;
  }
  return 0;
}

}  // namespace

std::optional<ExifLens> lens_from_exif(const io::PhotoMeta& meta, int width, int height) {
  if (width <= 0 || height <= 0) return std::nullopt;
  const double f = exif_number(meta, "Exif:FocalLength");
  const double xres = exif_number(meta, "Exif:FocalPlaneXResolution"),
               yres = exif_number(meta, "Exif:FocalPlaneYResolution");
  const double unit_code = exif_number(meta, "Exif:FocalPlaneResolutionUnit");
  const double unit_mm = unit_code == 3 ? 10.0 : unit_code == 4 ? 1.0 : unit_code == 2 || unit_code == 0 ? 25.4 : 0;
  if (f > 0 && (yres > 0 || xres > 0) && unit_mm > 0) {
    const double fy_px = f * (yres > 0 ? yres : xres) / unit_mm;  // pixels per mm of the sensor times mm
    ExifLens l;
    l.fov_y_deg = 2 * std::atan(height / (2 * fy_px)) * 180 / kPi;
    l.source = fmt::format("Exif FocalLength {:g} mm, focal plane {:g} px per {}", f, yres > 0 ? yres : xres,
                           unit_mm == 10  ? "cm"
                           : unit_mm == 1 ? "mm"
                                          : "inch");
    if (l.fov_y_deg > 0 && l.fov_y_deg < 179) return l;
  }
  const double f35 = exif_number(meta, "Exif:FocalLengthIn35mmFilm");
  if (f35 > 0) {
    // The 35 mm equivalent matches the diagonal: the frame's half-diagonal in pixels over f_px is 21.63 / f35.
    const double half_diag_px = std::hypot(width, height) / 2, fpx = half_diag_px * f35 / (std::hypot(36.0, 24.0) / 2);
    ExifLens l;
    l.fov_y_deg = 2 * std::atan(height / (2 * fpx)) * 180 / kPi;
    l.source = fmt::format("Exif FocalLengthIn35mmFilm {:g} mm (whole millimetres: about ±{:.1f}° of field of view)",
                           f35, l.fov_y_deg * 0.5 / f35);
    if (l.fov_y_deg > 0 && l.fov_y_deg < 179) return l;
  }
  return std::nullopt;
}

std::vector<io::PhotoAttribute> exif_lens_attributes(double fov_y_deg, int width, int height, double sensor_width_mm) {
  const double fy_px = height / (2 * std::tan(fov_y_deg * kPi / 360));
  const double px_per_cm = width / (sensor_width_mm / 10);  // square pixels
  const double f_mm = fy_px / px_per_cm * 10;
  const double f35 = f_mm * std::hypot(36.0, 24.0) / (sensor_width_mm * std::hypot(width, height) / width);
  return {{"Exif:FocalLength", "float", fmt::format("{:.9g}", f_mm)},
          {"Exif:FocalPlaneXResolution", "float", fmt::format("{:.9g}", px_per_cm)},
          {"Exif:FocalPlaneYResolution", "float", fmt::format("{:.9g}", px_per_cm)},
          {"Exif:FocalPlaneResolutionUnit", "int", "3"},
          {"Exif:FocalLengthIn35mmFilm", "int", fmt::format("{}", static_cast<int>(std::lround(f35)))}};
}

}  // namespace ibl::capture
