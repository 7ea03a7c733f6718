// iblkit camera solve | calibrate | check: the camera of a photograph (docs/camera.md). Parses and calls
// capture/camera_solve.h; OpenCV sits in the cv plugin, loaded by the library when a solve needs it.
#include <cmath>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/capture/camera_solve.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/photo.h"

namespace {

using ibl::ErrorKind;
using ibl::fail;
using ibl::Vec3;
using ibl::capture::Board;
using ibl::capture::Correspondence;
using ibl::geometry::Camera;

struct BoardOpts {
  std::string spec, origin = "0,0,0", axes = "1,0,0,0,0,-1";
};

void add_board_options(CLI::App* c, BoardOpts& b, bool required) {
  auto* o = c->add_option("--board", b.spec,
                          "the board in the photograph: checker:COLSxROWS:SQUARE_M (inner corners, metres; one "
                          "count odd, one even) or charuco:SQXxSQY:SQUARE_M:MARKER_M[:DICT] (squares; docs/camera.md)");
  if (required) o->required();
  c->add_option("--board-origin", b.origin, "world position of the board's first inner corner x,y,z (metres)")
      ->capture_default_str();
  c->add_option("--board-axes", b.axes,
                "ux,uy,uz,vx,vy,vz: the world directions of the board's columns (u) and rows (v); u × v points "
                "out of its printed face (default: on the floor, face up)")
      ->capture_default_str();
}

Board make_board(const BoardOpts& o) {
  Board b = ibl::capture::parse_board(o.spec, "--board");
  Vec3 origin = iblcli::parse_vec3(o.origin, "--board-origin");
  std::vector<double> a;
  std::stringstream ss(o.axes);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      a.push_back(std::stod(item, &used));
      if (used != item.size()) a.clear(), a.resize(7);
    } catch (const std::exception&) {
      a.clear();
      a.resize(7);
    }
  }
  if (a.size() != 6) fail(ErrorKind::Value, "--board-axes {}: expected six numbers ux,uy,uz,vx,vy,vz", o.axes);
  ibl::capture::place_board(b, origin, {a[0], a[1], a[2]}, {a[3], a[4], a[5]}, "--board-axes");
  return b;
}

std::vector<Correspondence> board_points(const std::string& photo, const Board& b, const std::string& spec) {
  ibl::Image img = ibl::io::read_image(photo);
  auto pts = ibl::capture::find_board(img, b);
  if (!pts) fail(ErrorKind::Value, "--board {}: no {} found in {} ({})", spec, b.describe(), photo, b.find_hint());
  return *pts;
}

nlohmann::json vec(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json lens_json(const Camera& c) {
  auto k = c.effective_intrinsics();
  nlohmann::json j = {{"fov_y_deg", c.fov_y_deg},
                      {"fx", k.fx},
                      {"fy", k.fy},
                      {"cx", k.cx},
                      {"cy", k.cy},
                      {"solved_intrinsics", c.intrinsics.has_value()}};
  if (c.distorted())
    j["distortion"] = {c.distortion.k1, c.distortion.k2, c.distortion.p1, c.distortion.p2, c.distortion.k3};
  return j;
}

void print_camera(const Camera& c) {
  fmt::print("eye       {:.6f}, {:.6f}, {:.6f}\n", c.eye.x, c.eye.y, c.eye.z);
  fmt::print("target    {:.6f}, {:.6f}, {:.6f}\n", c.target.x, c.target.y, c.target.z);
  fmt::print("up        {:.6f}, {:.6f}, {:.6f}\n", c.up.x, c.up.y, c.up.z);
  auto k = c.effective_intrinsics();
  fmt::print("lens      {}x{}, fov_y {:.4f}°, fx {:.3f}, fy {:.3f}, cx {:.3f}, cy {:.3f}{}\n", c.width, c.height,
             c.fov_y_deg, k.fx, k.fy, k.cx, k.cy, c.intrinsics ? "" : " (pinhole)");
  if (c.distorted())
    fmt::print("distortion k1 {:.6g}, k2 {:.6g}, p1 {:.6g}, p2 {:.6g}, k3 {:.6g}\n", c.distortion.k1, c.distortion.k2,
               c.distortion.p1, c.distortion.p2, c.distortion.k3);
}

struct SolveOpts {
  std::string photo, points, intrinsics, out;
  BoardOpts board;
  double fov = 0;
  double max_error = 5;
  bool no_exif = false;
};

void run_solve(const SolveOpts& o) {
  ibl::io::ImageSpec spec = ibl::io::read_image_spec(o.photo);
  if (o.points.empty() == o.board.spec.empty())
    fail(ErrorKind::Value, "camera solve: give either --points FILE or --board SPEC");
  if (o.fov != 0 && !o.intrinsics.empty())
    fail(ErrorKind::Value, "camera solve: --fov and --intrinsics both fix the lens; give one");
  Camera lens;
  lens.width = spec.width;
  lens.height = spec.height;
  ibl::capture::LensMode mode = ibl::capture::LensMode::SolveFocal;
  // The photograph's Exif focal length: the lens when nothing else gives one, and a check of --fov.
  std::optional<ibl::capture::ExifLens> exif;
  if (!o.no_exif && o.intrinsics.empty()) {
    try {
      exif = ibl::capture::lens_from_exif(ibl::io::read_photo(o.photo).meta, spec.width, spec.height);
    } catch (const ibl::Error& e) {
      if (e.kind() != ErrorKind::Format) throw;  // a float image: no Exif to read
    }
  }
  std::string lens_source = "focal length solved";
  if (o.fov != 0) {
    lens.fov_y_deg = ibl::require_number("--fov", o.fov, 1e-3, 179);
    if (exif && std::abs(exif->fov_y_deg - lens.fov_y_deg) > 1)
      fail(ErrorKind::Value, "--fov {}: {}'s {} gives {:.2f}°; drop --fov, or give --no-exif to overrule the file",
           o.fov, o.photo, exif->source, exif->fov_y_deg);
    mode = ibl::capture::LensMode::Fixed;
    lens_source = "--fov";
  } else if (exif) {
    lens.fov_y_deg = exif->fov_y_deg;
    mode = ibl::capture::LensMode::Fixed;
    lens_source = exif->source;
  } else if (!o.intrinsics.empty()) {
    Camera k = ibl::geometry::read_camera(o.intrinsics);
    if (!k.intrinsics) fail(ErrorKind::Value, "--intrinsics {}: the file has no \"intrinsics\"", o.intrinsics);
    if (k.width != spec.width || k.height != spec.height)
      fail(ErrorKind::Value, "--intrinsics {}: calibrated for {}x{}, but {} is {}x{}", o.intrinsics, k.width, k.height,
           o.photo, spec.width, spec.height);
    lens.intrinsics = k.intrinsics;
    lens.distortion = k.distortion;
    lens.fov_y_deg = k.fov_y_deg;
    mode = ibl::capture::LensMode::Fixed;
    lens_source = "--intrinsics " + o.intrinsics;
  }
  std::vector<Correspondence> pts;
  Board board;
  if (!o.points.empty()) {
    pts = ibl::capture::read_points(o.points);
  } else {
    board = make_board(o.board);
    pts = board_points(o.photo, board, o.board.spec);
  }
  const std::string source = o.points.empty() ? "--board " + o.board.spec : "--points " + o.points;
  ibl::capture::Solved s;
  try {
    s = o.points.empty() ? ibl::capture::solve_board_camera(board, pts, lens, mode)
                         : ibl::capture::solve_camera(pts, lens, mode);
  } catch (const ibl::Error& e) {
    fail(e.kind(), "{}: {}", source, e.what());
  }
  // The corners are labelled so that the camera sees the side u × v points to; on a floor (+Y up,
  // docs/conventions.md) axes whose u × v points down put the camera under it.
  if (!o.board.spec.empty()) {
    Vec3 n = cross(board.u, board.v);
    if (n.y < -0.9 && s.camera.eye.y < board.origin.y)
      fail(ErrorKind::Value,
           "--board-axes {}: u × v points down, so the camera comes out under the floor; give axes whose u × v "
           "points up (out of the board's printed face)",
           o.board.axes);
  }
  if (!(s.error.rms_px <= o.max_error))
    fail(ErrorKind::Value,
         "{}: the points disagree: reprojection error {:.3g} px RMS (worst: point {}, {:.3g} px) exceeds "
         "--max-error {} px",
         source, s.error.rms_px, s.error.worst, s.error.max_px, o.max_error);
  ibl::geometry::validate_camera(s.camera, "camera solve");
  ibl::geometry::write_camera(o.out, s.camera, true);
  nlohmann::json j = {{"camera", o.out},
                      {"points", pts.size()},
                      {"coplanar", s.coplanar},
                      {"dropped", s.dropped},
                      {"lens", mode == ibl::capture::LensMode::Fixed ? "fixed" : "focal solved"},
                      {"lens_source", lens_source},
                      {"eye", vec(s.camera.eye)},
                      {"target", vec(s.camera.target)},
                      {"up", vec(s.camera.up)},
                      {"intrinsics", lens_json(s.camera)},
                      {"reprojection_rms_px", s.error.rms_px},
                      {"reprojection_max_px", s.error.max_px}};
  iblcli::emit(j, [&] {
    fmt::print("solved    {} {} points{} ({}), lens {}\n", pts.size(), o.points.empty() ? "board" : "user",
               s.coplanar ? ", coplanar" : "", s.coplanar ? "IPPE" : "EPnP + iterative",
               mode == ibl::capture::LensMode::Fixed ? "fixed (" + lens_source + ")" : lens_source);
    print_camera(s.camera);
    fmt::print("reprojection error {:.4g} px RMS, {:.4g} px max\n", s.error.rms_px, s.error.max_px);
    if (s.dropped) fmt::print("dropped   {} corners as misread (over 3 x the median error)\n", s.dropped);
    fmt::print("wrote     {}\n", o.out);
  });
}

struct CalibrateOpts {
  std::vector<std::string> photos;
  BoardOpts board;
  std::string out;
};

void run_calibrate(const CalibrateOpts& o) {
  Board board = make_board(o.board);
  std::vector<std::vector<Correspondence>> views;
  int w = 0, h = 0;
  for (const auto& p : o.photos) {
    ibl::io::ImageSpec spec = ibl::io::read_image_spec(p);
    if (views.empty()) w = spec.width, h = spec.height;
    if (spec.width != w || spec.height != h)
      fail(ErrorKind::Value, "{}: {}x{}, but {} is {}x{}: one lens, one frame size", p, spec.width, spec.height,
           o.photos[0], w, h);
    views.push_back(board_points(p, board, o.board.spec));
  }
  ibl::capture::Calibrated c = ibl::capture::calibrate_camera(views, w, h);
  ibl::geometry::validate_camera(c.camera, "camera calibrate");
  ibl::geometry::write_camera(o.out, c.camera, true);
  nlohmann::json j = {{"camera", o.out},
                      {"photographs", o.photos.size()},
                      {"intrinsics", lens_json(c.camera)},
                      {"reprojection_rms_px", c.rms_px},
                      {"per_photograph_rms_px", c.per_view_rms_px},
                      {"std_dev", c.std_dev},
                      {"warnings", c.warnings}};
  for (const auto& w : c.warnings) iblcli::info("warning: " + w);
  iblcli::emit(j, [&] {
    fmt::print("calibrated {} photographs of a {}x{} board\n", o.photos.size(), board.cols, board.rows);
    print_camera(c.camera);
    fmt::print("reprojection error {:.4g} px RMS (calibrateCamera); per photograph:", c.rms_px);
    for (double e : c.per_view_rms_px) fmt::print(" {:.3g}", e);
    fmt::print("\nwrote     {} (the lens, and the pose of {})\n", o.out, o.photos[0]);
  });
}

struct CheckOpts {
  std::string photo, camera, points;
};

void run_check(const CheckOpts& o) {
  ibl::io::ImageSpec spec = ibl::io::read_image_spec(o.photo);
  Camera cam = ibl::geometry::read_camera(o.camera);
  if (cam.width == 0 && cam.height == 0) cam.width = spec.width, cam.height = spec.height;
  if (cam.width != spec.width || cam.height != spec.height)
    fail(ErrorKind::Value, "--camera {}: a {}x{} frame, but {} is {}x{}", o.camera, cam.width, cam.height, o.photo,
         spec.width, spec.height);
  ibl::geometry::require_camera(cam);
  auto pts = ibl::capture::read_points(o.points);
  auto r = ibl::capture::reprojection(cam, pts);
  if (r.behind)
    fail(ErrorKind::Value, "--points {}: {} of the {} points lie behind the camera of {}", o.points, r.behind,
         pts.size(), o.camera);
  nlohmann::json per = nlohmann::json::array();
  for (const auto& p : pts) {
    auto q = cam.project(p.world);
    per.push_back({{"pixel", {p.pixel.x, p.pixel.y}},
                   {"projected", {q->x, q->y}},
                   {"error_px", std::hypot(q->x - p.pixel.x, q->y - p.pixel.y)}});
  }
  nlohmann::json j = {{"camera", o.camera},
                      {"points", per},
                      {"reprojection_rms_px", r.rms_px},
                      {"reprojection_max_px", r.max_px},
                      {"worst", r.worst}};
  iblcli::emit(j, [&] {
    fmt::print("{:>5} {:>21} {:>21} {:>10}\n", "point", "pixel", "projected", "error px");
    for (size_t i = 0; i < per.size(); ++i)
      fmt::print("{:>5} {:>10.3f},{:>10.3f} {:>10.3f},{:>10.3f} {:>10.4f}\n", i, per[i]["pixel"][0].get<double>(),
                 per[i]["pixel"][1].get<double>(), per[i]["projected"][0].get<double>(),
                 per[i]["projected"][1].get<double>(), per[i]["error_px"].get<double>());
    fmt::print("reprojection error {:.4g} px RMS, {:.4g} px max (point {})\n", r.rms_px, r.max_px, r.worst);
  });
}

void setup(CLI::App& app) {
  app.require_subcommand(1);
  app.footer(
      "Examples:\n  iblkit camera solve photo.jpg --points pts.json --fov 40 --out cam.json\n"
      "  iblkit camera solve photo.jpg --board checker:9x6:0.05 --board-origin 0,0,0 --board-axes 1,0,0,0,0,-1 "
      "--intrinsics lens.json --out cam.json\n"
      "  iblkit camera calibrate board*.jpg --board checker:9x6:0.025 --out lens.json\n"
      "  iblkit camera check photo.jpg --camera cam.json --points pts.json");

  auto* s = app.add_subcommand("solve", "The camera of a photograph from pixel ↔ world points or a chessboard");
  auto* so = iblcli::app_owned<SolveOpts>();
  s->add_option("photo", so->photo, "the photograph (its size; its pixels with --board)")->required();
  s->add_option("--points", so->points, "iblkit.points/1: at least 6 pixel ↔ world pairs (docs/formats.md)");
  add_board_options(s, so->board, false);
  s->add_option("--fov", so->fov, "fix the lens: an undistorted pinhole of this vertical field of view (degrees)");
  s->add_flag("--no-exif", so->no_exif,
              "do not take the lens from the photograph's Exif (FocalLength with the focal plane's resolution, or "
              "FocalLengthIn35mmFilm)");
  s->add_option("--intrinsics", so->intrinsics,
                "fix the lens: an iblkit.camera/1 file with intrinsics and distortion (camera calibrate's)");
  s->add_option("--max-error", so->max_error, "refuse a solve whose RMS reprojection error exceeds this (px)")
      ->capture_default_str();
  s->add_option("-o,--out", so->out, "the camera file to write (iblkit.camera/1)")->required();
  s->footer(
      "Without --fov, --intrinsics or an Exif focal length one focal length is solved with the pose (centred principal "
      "point, no "
      "distortion).\nExamples:\n  iblkit camera solve photo.jpg --points pts.json --fov 40 --out cam.json\n"
      "  iblkit camera solve photo.jpg --board checker:9x6:0.05 --board-origin 0,0,0 --board-axes 1,0,0,0,0,-1 "
      "--intrinsics lens.json --out cam.json");
  s->callback([so] { run_solve(*so); });

  auto* c = app.add_subcommand("calibrate", "A lens (intrinsics, distortion) from several photographs of a board");
  auto* co = iblcli::app_owned<CalibrateOpts>();
  c->add_option("photos", co->photos, "three or more photographs of the board, one camera and zoom")->required();
  add_board_options(c, co->board, true);
  c->add_option("-o,--out", co->out, "the camera file to write: the lens and the first photograph's pose")->required();
  c->footer(
      "Example:\n  iblkit camera calibrate b1.jpg b2.jpg b3.jpg b4.jpg --board checker:9x6:0.025 --out lens.json");
  c->callback([co] { run_calibrate(*co); });

  auto* k = app.add_subcommand("check", "The reprojection error of points through a camera file");
  auto* ko = iblcli::app_owned<CheckOpts>();
  k->add_option("photo", ko->photo, "the photograph (its size)")->required();
  k->add_option("--camera", ko->camera, "iblkit.camera/1")->required();
  k->add_option("--points", ko->points, "iblkit.points/1")->required();
  k->footer("Example:\n  iblkit camera check photo.jpg --camera cam.json --points pts.json");
  k->callback([ko] { run_check(*ko); });
}

iblcli::Command reg("camera", setup);

}  // namespace
