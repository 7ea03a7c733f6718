// iblkit lab capture SCENE …, iblkit lab truth SCENE --at x,y,z … and iblkit lab photograph SCENE …:
// synthetic probes, probe sequences and fusion probe sets of analytic scenes, their exact ground truth,
// and pinhole photographs with or without an inserted object (docs/lab.md).
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/capture/camera_solve.h"
#include "iblkit/capture/folder.h"
#include "iblkit/capture/response.h"
#include "iblkit/capture/sensor.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/io/dng.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/photo.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/capture.h"
#include "iblkit/lab/plate.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
#include "iblkit/lab/shoot.h"
#include "iblkit/lab/truth.h"
#include "iblkit/lab/view.h"
#include "iblkit/render/objects.h"
#include "iblkit/sh/coeffs.h"
#include "render_setup.h"

namespace {

namespace fs = std::filesystem;
using ibl::Vec3;

// "x,y,z;x,y,z;…" -> points.
std::vector<Vec3> parse_points(const std::string& s, const std::string& what) {
  std::vector<Vec3> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ';'))
    if (!part.empty()) out.push_back(iblcli::parse_vec3(part, what));
  if (out.empty()) ibl::fail(ibl::ErrorKind::Value, "{}: expected points \"x,y,z;x,y,z;…\", got \"{}\"", what, s);
  return out;
}

struct CaptureOpts {
  std::string scene, out, mapping = "latlong", camera = "ideal", grid, path, volume, format = "exr", look = "0,0,1";
  std::vector<std::string> probes;
  int size = 64, samples = 1, count = 10, random = 0, clusters = 0, bounces = -1, area_samples = 0, env_samples = 0;
  double dead_angle = 0, ball_radius = 0.04, reflectance = 1, cluster_spread = 0.1;
  uint64_t seed = 0;
  bool depth = false, fusion = false, parallax = false, half = false;
};

void run_capture(const CaptureOpts& o) {
  ibl::lab::Scene scene = ibl::lab::load_scene(o.scene);
  Vec3 lo = scene.volume_min, hi = scene.volume_max;
  if (!o.volume.empty()) {
    auto v = parse_points(o.volume, "--volume");
    if (v.size() != 2) ibl::fail(ibl::ErrorKind::Value, "--volume: expected \"x0,y0,z0;x1,y1,z1\"");
    lo = v[0];
    hi = v[1];
  }
  int modes = !o.probes.empty() + !o.grid.empty() + !o.path.empty() + (o.random > 0);
  if (modes != 1) ibl::fail(ibl::ErrorKind::Value, "give exactly one of --probe, --grid, --path, --random");
  std::vector<Vec3> pos;
  for (const auto& p : o.probes) pos.push_back(iblcli::parse_vec3(p, "--probe"));
  if (!o.grid.empty()) {
    auto n = iblcli::parse_int_list(o.grid, "--grid");
    if (n.size() != 3) ibl::fail(ibl::ErrorKind::Value, "--grid: expected nx,ny,nz");
    pos = ibl::lab::grid_positions(lo, hi, n[0], n[1], n[2]);
  }
  if (!o.path.empty()) pos = ibl::lab::path_positions(parse_points(o.path, "--path"), o.count);
  ibl::lab::SequenceDesc d;
  d.capture.render = scene.render;
  if (o.bounces >= 0) d.capture.render.bounces = o.bounces;
  if (o.area_samples > 0) d.capture.render.area_samples = o.area_samples;
  if (o.env_samples > 0) d.capture.render.env_samples = o.env_samples;
  if (o.seed > 0) d.capture.render.seed = o.seed;
  if (o.clusters > 0 && o.random < 1)
    ibl::fail(ibl::ErrorKind::Value, "--clusters N needs --random M (M positions in N clusters)");
  if (o.random > 0)
    pos = o.clusters > 0
              ? ibl::lab::cluster_positions(lo, hi, o.clusters, o.random, o.cluster_spread, d.capture.render.seed)
              : ibl::lab::random_positions(lo, hi, o.random, d.capture.render.seed);
  d.capture.mapping = ibl::sphere::parse_mapping(o.mapping);
  d.capture.size = o.size;
  d.capture.samples = o.samples;
  d.capture.dead_angle_deg = o.dead_angle;
  {  // --look: the world direction of the probe's +Z (a mirror ball's centre; its dead angle is opposite)
    Vec3 z = iblcli::parse_vec3(o.look, "--look");
    if (length(z) == 0) ibl::fail(ibl::ErrorKind::Value, "--look: (0,0,0) has no direction");
    z = normalize(z);
    Vec3 up = std::abs(z.y) > 0.999 ? Vec3{0, 0, -z.y} : Vec3{0, 1, 0};  // keep +Y up where possible
    Vec3 x = normalize(cross(up, z)), y = cross(z, x);
    d.capture.rotation = ibl::Mat3::rows(x, y, z).transposed();  // columns: the probe's axes in the world
  }
  if (o.camera != "ideal" && o.camera != "ball")
    ibl::fail(ibl::ErrorKind::Value, "--camera: expected ideal or ball, got {}", o.camera);
  d.capture.camera = o.camera == "ball" ? ibl::lab::Camera::MirrorBall : ibl::lab::Camera::Ideal;
  if (d.capture.camera == ibl::lab::Camera::MirrorBall) d.capture.mapping = ibl::sphere::MappingKind::MirrorBall;
  d.capture.ball_radius = o.ball_radius;
  d.capture.ball_parallax = o.parallax;
  d.capture.ball_reflectance = o.reflectance;
  d.capture.depth = o.depth;
  d.out_dir = o.out;
  d.frame_ext = "." + o.format;
  d.half = o.half;
  auto bar = iblcli::progress_bar();
  ibl::lab::SequenceResult r =
      o.fusion ? ibl::lab::write_probe_set(scene, pos, d, bar) : ibl::lab::write_sequence(scene, pos, d, bar);
  iblcli::progress_done();
  nlohmann::json j = {{"scene", scene.name},
                      {"manifest", r.manifest},
                      {"contact_sheet", r.contact_sheet},
                      {"probes", r.probes},
                      {"seconds", r.seconds},
                      {"mapping", ibl::sphere::mapping_name(d.capture.mapping)},
                      {"size", d.capture.size},
                      {"probes_per_second", r.seconds > 0 ? r.probes / r.seconds : 0.0}};
  iblcli::emit(j, [&] {
    fmt::print("captured {} probe{} of {} in {:.2f} s ({:.1f} probes/s)\n  manifest:      {}\n  contact sheet: {}\n",
               r.probes, r.probes == 1 ? "" : "s", scene.name, r.seconds, r.probes / std::max(r.seconds, 1e-9),
               r.manifest, r.contact_sheet);
  });
}

struct TruthOpts {
  std::string scene, at, out;
  std::vector<std::string> normals;
  int size = 128, samples = 4, area_samples = 64, bands = 3;
  uint64_t seed = 1;
  double blind_cone = 0;
  std::string blind_axis = "0,0,-1";
};

void run_truth(const TruthOpts& o) {
  ibl::lab::Scene scene = ibl::lab::load_scene(o.scene);
  ibl::lab::TruthDesc d;
  d.size = o.size;
  d.samples = o.samples;
  d.area_samples = o.area_samples;
  d.bands = o.bands;
  d.seed = o.seed;
  d.blind_cone_deg = o.blind_cone;
  d.blind_axis = iblcli::parse_vec3(o.blind_axis, "--blind-axis");
  for (const auto& n : o.normals) d.normals.push_back(iblcli::parse_vec3(n, "--normal"));
  if (d.normals.empty()) d.normals = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  Vec3 at = iblcli::parse_vec3(o.at, "--at");
  auto t = ibl::lab::ground_truth(scene, at, d, iblcli::progress_bar());
  iblcli::progress_done();
  auto rgb = [](Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json j = {{"scene", scene.name}, {"position", rgb(at)}, {"size", d.size}};
  nlohmann::json irr = nlohmann::json::array();
  for (size_t i = 0; i < t.normals.size(); ++i)
    irr.push_back({{"normal", rgb(t.normals[i])}, {"irradiance", rgb(t.irradiance[i])}});
  j["irradiance"] = irr;
  if (d.bands > 0) j["sh"] = ibl::sh::to_json(t.sh);
  if (!t.sh_visible.c.empty()) j["sh_visible"] = ibl::sh::to_json(t.sh_visible);
  if (!o.out.empty()) {
    ibl::make_output_folders(fs::path(o.out).string());
    fs::path out(o.out);
    ibl::io::write_image((out / "radiance.exr").string(), t.radiance.image);
    ibl::io::write_image((out / "radiance.png").string(), ibl::io::tonemap(t.radiance.image));
    if (d.bands > 0) ibl::sh::write_coeffs((out / "sh.json").string(), t.sh);
    if (!t.sh_visible.c.empty()) ibl::sh::write_coeffs((out / "sh_visible.json").string(), t.sh_visible);
    ibl::write_json_file((out / "truth.json").string(), j);
    j["out"] = o.out;
  }
  iblcli::emit(j, [&] {
    fmt::print("ground truth of {} at ({}, {}, {}), {}x{} lat-long\n", scene.name, at.x, at.y, at.z, 2 * d.size,
               d.size);
    fmt::print("  {:>26}  {:>30}\n", "normal", "irradiance (W/m², RGB)");
    for (size_t i = 0; i < t.normals.size(); ++i)
      fmt::print("  ({:7.3f} {:7.3f} {:7.3f})  ({:9.4f} {:9.4f} {:9.4f})\n", t.normals[i].x, t.normals[i].y,
                 t.normals[i].z, t.irradiance[i].x, t.irradiance[i].y, t.irradiance[i].z);
    if (!t.sh.c.empty())
      fmt::print("  SH c00: ({:.4f} {:.4f} {:.4f}), {} bands\n", t.sh.c[0].x, t.sh.c[0].y, t.sh.c[0].z, d.bands);
    if (!o.out.empty())
      fmt::print("  wrote {}/radiance.exr, radiance.png, truth.json{}\n", o.out, d.bands > 0 ? ", sh.json" : "");
  });
}

struct PhotoOpts {
  std::string scene, out, eye = "0,1.2,2.4", target = "0,0.6,0", up = "0,1,0", camera, object, at = "0,0.3,0",
                          albedo = "0.7,0.7,0.7", mask;
  double fov = 40, object_size = 0.3;
  int width = 640, height = 480, samples = 4, bounces = 1, area_samples = 0, env_samples = 0, triangles = 20000;
  uint64_t seed = 1;
};

void run_photograph(const PhotoOpts& o) {
  ibl::lab::Scene scene = ibl::lab::load_scene(o.scene, false);
  ibl::geometry::Camera cam;
  if (!o.camera.empty()) {
    cam = ibl::geometry::read_camera(o.camera);
  } else {
    cam.eye = iblcli::parse_vec3(o.eye, "--eye");
    cam.target = iblcli::parse_vec3(o.target, "--target");
    cam.up = iblcli::parse_vec3(o.up, "--up");
    cam.fov_y_deg = o.fov;
  }
  if (o.camera.empty() || cam.width == 0) cam.width = o.width;
  if (o.camera.empty() || cam.height == 0) cam.height = o.height;
  ibl::geometry::validate_camera(cam, o.camera.empty() ? "the camera" : o.camera);
  int object = -1;
  if (!o.object.empty()) {
    const ibl::render::ObjectDesc od = iblcli::inserted_object(o.object, o.object_size, o.triangles, o.at);
    const ibl::render::Material material = iblcli::object_material(o.albedo, 0, 20, "phong", "");
    ibl::render::check_material(material, "--albedo");
    object = ibl::lab::add_object(scene, "object", ibl::render::make_object(od), material.albedo);
  }
  scene.build();
  ibl::lab::ViewDesc vd;
  vd.width = cam.width;
  vd.height = cam.height;
  vd.samples = o.samples;
  vd.render = scene.render;
  vd.render.bounces = o.bounces;
  if (o.area_samples > 0) vd.render.area_samples = o.area_samples;
  if (o.env_samples > 0) vd.render.env_samples = o.env_samples;
  vd.render.seed = o.seed;
  auto t0 = std::chrono::steady_clock::now();
  ibl::lab::View v = ibl::lab::photograph(
      scene,
      [&](double px, double py, Vec3* org, Vec3* dir) {
        *org = cam.eye;
        *dir = cam.ray_direction(px, py);
      },
      vd, iblcli::progress_bar());
  iblcli::progress_done();
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ibl::io::write_image(o.out, v.radiance);
  int64_t object_pixels = 0;
  if (!o.mask.empty()) {
    ibl::Image m(cam.width, cam.height, 1);
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x)
        if (object >= 0 && static_cast<int>(v.surface.at(x, y, 0)) == object) m.at(x, y, 0) = 1;
    ibl::io::write_image(o.mask, m);
  }
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x)
      object_pixels += object >= 0 && static_cast<int>(v.surface.at(x, y, 0)) == object;
  nlohmann::json j = {{"scene", scene.name},
                      {"out", o.out},
                      {"width", cam.width},
                      {"height", cam.height},
                      {"seconds", secs},
                      {"bounces", vd.render.bounces},
                      {"object_pixels", object_pixels},
                      {"camera", ibl::geometry::camera_to_json(cam)}};
  if (!o.mask.empty()) j["mask"] = o.mask;
  iblcli::emit(j, [&] {
    fmt::print("photographed {} ({}x{}, {}x{} rays per pixel, {} bounce{}) in {:.2f} s: {}\n", scene.name, cam.width,
               cam.height, o.samples, o.samples, vd.render.bounces, vd.render.bounces == 1 ? "" : "s", secs, o.out);
    if (object >= 0)
      fmt::print("  the object covers {} pixel centres{}\n", object_pixels, o.mask.empty() ? "" : "; mask: " + o.mask);
  });
}

struct ShootOpts {
  std::string scene, out, at = "0,1,0", views = "0", reflectance, fresnel = "chrome", response = "srgb", format = "jpg",
                          wb = "1,1,1", exposure, chroma;
  double ball_radius = 0.05, distance = 0.5, distance_radii = 0, azimuth = 0, elevation = 0, fill = 0.9, ev_step = 2,
         fnumber = 8, iso = 100, full_well = 0, read_noise = 0, vignetting = 0;
  int width = 512, height = 512, samples = 2, truth_size = 128, bracket = 0, quality = 95, shift = 0, area_samples = 0,
      bounces = -1;
  uint64_t seed = 1;
  bool two_sides = false, no_photographer = false, noise = false, until_unsaturated = false;
  // --backplate: the scene photographed with a board on the floor, the truth with the object, capture.json.
  bool backplate = false;
  std::string plate_eye = "0.3,1.4,2.2", plate_target = "0,0.2,0", plate_wb = "1,1,1", plate_exposure,
              board = "7x4:0.1", board_at = "-0.4,0,0.9", object = "blob", object_at = "0,0.161,0",
              albedo = "0.7,0.7,0.7";
  double plate_fov = 50, plate_k1 = 0, object_size = 0.3;
  int plate_width = 320, plate_height = 240, plate_samples = 8;
};

// --board: COLSxROWS:SQUARE_M is a checker's inner corners; a full spec (checker:…, charuco:…) is taken as it is.
std::string board_spec(const std::string& b) {
  return b.rfind("checker:", 0) == 0 || b.rfind("charuco:", 0) == 0 ? b : "checker:" + b;
}

// lab shoot --backplate: the backplate (the scene with the board printed on the floor, no object), the truth (the
// same photograph with the object), their camera, the proxy, and capture.json naming the views' brackets.
nlohmann::json shoot_backplate(const ShootOpts& o, const ibl::lab::ShootDesc& d, const ibl::lab::BracketDesc& bd,
                               const nlohmann::json& jviews, const fs::path& out) {
  ibl::lab::Scene scene = ibl::lab::load_scene(o.scene, false);
  const ibl::geometry::TriMesh proxy = scene.proxy_mesh();
  ibl::capture::Board board = ibl::capture::parse_board(board_spec(o.board), "--board");
  const Vec3 centre = iblcli::parse_vec3(o.board_at, "--board-at");
  const Vec3 u{1, 0, 0}, v{0, 0, -1};  // on the floor, face up
  const Vec3 origin = centre - (u * ((board.cols - 1) / 2.0) + v * ((board.rows - 1) / 2.0)) * board.square;
  ibl::capture::place_board(board, origin, u, v, "--board-at");
  ibl::lab::add_board(scene, board);
  ibl::lab::PlateDesc pd;
  ibl::geometry::Camera& cam = pd.camera;
  cam.eye = iblcli::parse_vec3(o.plate_eye, "--plate-eye");
  cam.target = iblcli::parse_vec3(o.plate_target, "--plate-target");
  cam.fov_y_deg = ibl::require_number("--plate-fov", o.plate_fov, 1, 150);
  cam.width = o.plate_width;
  cam.height = o.plate_height;
  if (o.plate_k1 != 0) {  // a lens with barrel (k1 < 0) or pincushion distortion
    cam.intrinsics = cam.effective_intrinsics();
    cam.distortion.k1 = ibl::require_number("--plate-k1", o.plate_k1, -1, 1);
  }
  ibl::geometry::validate_camera(cam, "--plate-eye/--plate-target");
  pd.samples = o.plate_samples;
  pd.sensor = bd.sensor;
  pd.sensor.wb_gains = iblcli::parse_vec3(o.plate_wb, "--plate-wb");
  pd.sensor.exposure_s =
      o.plate_exposure.empty() ? 0 : iblcli::parse_double_list(o.plate_exposure, "--plate-exposure").at(0);
  pd.sensor.seed = o.seed + 5000;
  const ibl::render::ObjectDesc od = iblcli::inserted_object(o.object, o.object_size, 20000, o.object_at);
  const ibl::render::Material material = iblcli::object_material(o.albedo, 0, 20, "phong", "");
  ibl::render::check_material(material, "--albedo");
  pd.object = ibl::render::make_object(od);
  pd.albedo = material.albedo;
  // The room's light is the one the ball saw: the same bounces (a real room has them all; with B the object in the
  // truth meets walls lit with B − 1, the B-th bounce is what the composite's probe has more).
  pd.render = d.render;
  ibl::lab::Plate plate = ibl::lab::shoot_plate(scene, pd, iblcli::progress_bar());
  iblcli::progress_done();
  ibl::io::PhotoMeta pm;
  pm.exposure_time = plate.exposure_s;
  pm.f_number = pd.sensor.f_number;
  pm.iso = pd.sensor.iso;
  pm.make = "iblkit";
  pm.model = "lab shoot";
  pm.attributes = ibl::capture::exif_lens_attributes(cam.fov_y_deg, cam.width, cam.height);
  if (!o.chroma.empty()) pm.attributes.push_back({"jpeg:subsampling", "string", o.chroma});
  const std::string ext = o.format;
  if (bd.raw) {  // raw files of the same shot: the same light and noise, no curve
    ibl::io::write_dng((out / ("backplate." + ext)).string(),
                       ibl::capture::expose_dng(plate.backplate_radiance, plate.sensor, *bd.raw, pm));
    ibl::io::write_dng((out / ("truth." + ext)).string(),
                       ibl::capture::expose_dng(plate.truth_radiance, plate.sensor, *bd.raw, pm));
  } else {
    ibl::io::write_photo((out / ("backplate." + ext)).string(), plate.backplate, pd.sensor.bits, pm, o.quality);
    ibl::io::write_photo((out / ("truth." + ext)).string(), plate.truth, pd.sensor.bits, pm, o.quality);
  }
  ibl::io::write_image((out / "truth_mask.png").string(), plate.truth_mask);
  ibl::geometry::write_camera((out / "camera_truth.json").string(), cam, true);
  ibl::geometry::write_obj((out / "proxy.obj").string(), proxy, "lab shoot --backplate: the proxy of " + scene.name);
  ibl::capture::CaptureFolder f;
  f.backplate = "backplate." + ext;
  // The camera's curve, as a user who calibrated it once (hdr merge --response-out) names it; without "response"
  // the chain recovers one from the ball's brackets (docs/capture.md measures both).
  f.response = bd.raw ? "linear" : "response.json";  // a raw file is linear
  f.board_spec = board_spec(o.board);
  f.board = board;
  if (cam.intrinsics) {  // the lens as `camera calibrate` would have found it beforehand
    ibl::geometry::Camera lens = cam;
    ibl::geometry::write_camera((out / "lens.json").string(), lens, true);
    f.lens = "lens.json";
  }
  f.ball_center = d.ball_center;
  f.ball_radius = d.ball_radius;
  const double az = d.azimuth_deg * ibl::kPi / 180, el = d.elevation_deg * ibl::kPi / 180;
  f.facing = {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
  f.fresnel = o.fresnel;
  if (d.reflectance.r0) f.reflectance = d.reflectance.r0;
  for (const auto& jv : jviews) {
    ibl::capture::CaptureView cv;
    for (const auto& fr : jv["frames"]) cv.frames.push_back(fr["file"].get<std::string>());
    cv.angle_deg = jv["angle_deg"].get<double>();
    cv.distance_radii = jv["distance_radii"].get<double>();
    const auto& b = jv["ball"];  // the silhouette as the lab drew it (a user's folder may leave it to the fit)
    cv.ball = ibl::capture::BallCircle{b[0].get<double>(), b[1].get<double>(), b[2].get<double>()};
    f.views.push_back(cv);
  }
  f.proxy = "proxy.obj";
  f.object = o.object;
  f.object_size = o.object_size;
  f.object_at = od.at;
  f.albedo = material.albedo;
  f.truth = "truth." + ext;
  f.truth_mask = "truth_mask.png";
  f.truth_camera = "camera_truth.json";
  ibl::write_json_file((out / "capture.json").string(), ibl::capture::capture_to_json(f));
  return {{"backplate", f.backplate},
          {"truth", f.truth},
          {"exposure_s", plate.exposure_s},
          {"saturated_pixels", plate.saturated},
          {"width", cam.width},
          {"height", cam.height},
          {"board", f.board_spec},
          {"capture", "capture.json"}};
}

void run_shoot(const ShootOpts& o) {
  if (o.backplate && o.bracket == 0)  // before anything is shot or written
    ibl::fail(ibl::ErrorKind::Value, "--backplate: the ball needs its brackets (--bracket N)");
  if (o.backplate) ibl::capture::parse_board(board_spec(o.board), "--board");
  ibl::lab::Scene scene = ibl::lab::load_scene(o.scene, false);
  ibl::lab::ShootDesc d;
  d.ball_center = iblcli::parse_vec3(o.at, "--at");
  d.ball_radius = o.ball_radius;
  d.distance = o.distance_radii > 0 ? o.distance_radii * o.ball_radius : o.distance;
  d.azimuth_deg = o.azimuth;
  d.elevation_deg = o.elevation;
  d.views_deg = o.two_sides ? std::vector<double>{0, 90} : iblcli::parse_double_list(o.views, "--views");
  d.width = o.width;
  d.height = o.height;
  d.fill = o.fill;
  d.samples = o.samples;
  d.photographer = !o.no_photographer;
  d.render = scene.render;
  if (o.area_samples > 0) d.render.area_samples = o.area_samples;
  if (o.bounces >= 0) d.render.bounces = o.bounces;
  d.render.seed = o.seed;
  ibl::capture::parse_fresnel(o.fresnel, &d.reflectance);
  if (!o.reflectance.empty()) {
    auto r = iblcli::parse_double_list(o.reflectance, "--reflectance");
    if (r.size() != 1 && r.size() != 3)
      ibl::fail(ibl::ErrorKind::Value, "--reflectance: expected r or r,g,b, got \"{}\"", o.reflectance);
    d.reflectance.r0 = r.size() == 1 ? Vec3{r[0], r[0], r[0]} : Vec3{r[0], r[1], r[2]};
  }
  ibl::lab::BracketDesc bd;
  if (o.bracket > 0) {
    bd.sensor.f_number = o.fnumber;
    bd.sensor.iso = o.iso;
    bd.sensor.response = ibl::capture::response_by_name(o.response);
    bd.sensor.bits = o.format == "jpg" ? 8 : 16;
    if (o.format != "jpg" && o.format != "tif" && o.format != "dng")
      ibl::fail(ibl::ErrorKind::Value, "--format: expected jpg (8-bit), tif (16-bit) or dng (14-bit raw), got {}",
                o.format);
    if (o.format == "dng") bd.raw = ibl::capture::RawSensor{};
    bd.sensor.full_well = o.noise && o.full_well == 0 ? 20000 : o.full_well;
    bd.sensor.read_noise = o.noise && o.read_noise == 0 ? 0.001 : o.read_noise;
    bd.sensor.vignetting = o.vignetting;
    bd.sensor.wb_gains = iblcli::parse_vec3(o.wb, "--wb");
    bd.sensor.seed = o.seed;
    bd.shift_px = o.shift;
    ibl::capture::validate(bd.sensor);
  }
  auto t0 = std::chrono::steady_clock::now();
  auto shots = ibl::lab::shoot(scene, d, iblcli::progress_bar());
  iblcli::progress_done();
  fs::path out(o.out);
  ibl::make_output_folders(out.string());
  nlohmann::json jviews = nlohmann::json::array();
  for (size_t v = 0; v < shots.size(); ++v) {
    const auto& s = shots[v];
    std::string base = fmt::format("view{}", v);
    ibl::io::write_image((out / (base + ".exr")).string(), s.radiance);
    ibl::io::write_image((out / (base + "_occluder.exr")).string(), s.occluder);
    ibl::io::write_image((out / (base + ".png")).string(), ibl::io::tonemap(s.radiance));
    nlohmann::json jv = {{"radiance", base + ".exr"},          {"occluder", base + "_occluder.exr"},
                         {"angle_deg", s.angle_deg},           {"ball", {s.ball.cx, s.ball.cy, s.ball.r}},
                         {"distance_radii", s.distance_radii}, {"camera", ibl::geometry::camera_to_json(s.camera)}};
    if (o.bracket > 0) {
      double middle = o.exposure.empty() ? ibl::lab::middle_grey_exposure(s.radiance, s.ball, bd.sensor)
                                         : iblcli::parse_double_list(o.exposure, "--exposure").at(0);
      if (o.until_unsaturated) {  // one step over middle grey, then shorter until nothing saturates
        ibl::capture::SensorDesc meter = bd.sensor;
        if (bd.raw)  // a raw file is decoded with the white balance's multipliers over the smallest: they clip at 1
          meter.wb_gains = meter.wb_gains / std::min({meter.wb_gains.x, meter.wb_gains.y, meter.wb_gains.z});
        bd.exposures_s =
            ibl::lab::bracket_until_unsaturated(s.radiance, meter, middle * std::exp2(o.ev_step), o.ev_step, o.bracket);
      } else if (v == 0 || o.exposure.empty())
        bd.exposures_s = ibl::lab::bracket_times(o.bracket, o.ev_step, middle);
      ibl::capture::SensorDesc sd = bd.sensor;
      ibl::lab::BracketDesc b = bd;
      b.sensor.seed = bd.sensor.seed + 1000 * v;
      auto frames = ibl::lab::bracket(s.radiance, b);
      nlohmann::json jf = nlohmann::json::array();
      for (size_t k = 0; k < frames.size(); ++k) {
        std::string name = fmt::format("{}_e{}.{}", base, k, o.format);
        ibl::io::PhotoMeta pm;
        pm.exposure_time = frames[k].exposure_s;
        pm.f_number = sd.f_number;
        pm.iso = sd.iso;
        pm.make = "iblkit";
        pm.model = "lab shoot";
        if (!o.chroma.empty()) pm.attributes.push_back({"jpeg:subsampling", "string", o.chroma});
        if (b.raw) {
          frames[k].raw.meta = pm;
          ibl::io::write_dng((out / name).string(), frames[k].raw);
        } else {
          ibl::io::write_photo((out / name).string(), frames[k].codes, sd.bits, pm, o.quality);
        }
        jf.push_back({{"file", name},
                      {"exposure_s", frames[k].exposure_s},
                      {"f_number", sd.f_number},
                      {"iso", sd.iso},
                      {"shift", {frames[k].dx, frames[k].dy}}});
      }
      jv["frames"] = jf;
    }
    jviews.push_back(jv);
  }
  if (o.bracket > 0) ibl::capture::write_response((out / "response.json").string(), bd.sensor.response);
  nlohmann::json jplate;
  if (o.backplate) jplate = shoot_backplate(o, d, bd, jviews, out);
  nlohmann::json j = {{"scene", scene.name},
                      {"ball_center", {d.ball_center.x, d.ball_center.y, d.ball_center.z}},
                      {"ball_radius", d.ball_radius},
                      {"distance_m", d.distance},
                      {"photographer", d.photographer},
                      {"width", d.width},
                      {"height", d.height},
                      {"views", jviews}};
  if (o.bracket > 0)
    j["sensor"] = {{"response", bd.sensor.response.kind},
                   {"response_file", "response.json"},
                   {"f_number", bd.sensor.f_number},
                   {"iso", bd.sensor.iso},
                   {"full_well", bd.sensor.full_well},
                   {"read_noise", bd.sensor.read_noise},
                   {"vignetting", bd.sensor.vignetting},
                   {"wb_gains", {bd.sensor.wb_gains.x, bd.sensor.wb_gains.y, bd.sensor.wb_gains.z}},
                   {"bits", bd.sensor.bits},
                   {"quality", o.quality},
                   {"shift_px", bd.shift_px}};
  if (o.truth_size > 0) {
    ibl::lab::Scene ts = ibl::lab::load_scene(o.scene, true);
    ibl::lab::TruthDesc td;
    td.size = o.truth_size;
    td.bands = 0;
    td.seed = o.seed;
    ts.render.bounces = d.render.bounces;  // the light the ball saw
    auto t = ibl::lab::ground_truth(ts, d.ball_center, td, iblcli::progress_bar());
    iblcli::progress_done();
    ibl::io::write_image((out / "truth.exr").string(), t.radiance.image);
    j["truth"] = "truth.exr";
  }
  if (o.backplate) j["backplate"] = jplate;
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ibl::write_json_file((out / "shoot.json").string(), j);
  j["out"] = o.out;
  iblcli::emit(j, [&] {
    fmt::print(
        "shot a chrome ball (r {} m) in {} at ({}, {}, {}) from {:.3f} m ({:.1f} radii), {} view{}, {}x{} in {:.2f} "
        "s\n",
        d.ball_radius, scene.name, d.ball_center.x, d.ball_center.y, d.ball_center.z, d.distance,
        d.distance / d.ball_radius, shots.size(), shots.size() == 1 ? "" : "s", d.width, d.height,
        j["seconds"].get<double>());
    for (size_t v = 0; v < shots.size(); ++v)
      fmt::print("  view{}: {}°, ball {:.1f},{:.1f},{:.1f} px{}\n", v, shots[v].angle_deg, shots[v].ball.cx,
                 shots[v].ball.cy, shots[v].ball.r,
                 o.bracket > 0 ? fmt::format(", {} {} frames", jviews[v]["frames"].size(), o.format) : std::string());
    if (o.backplate)
      fmt::print("  backplate {}x{} with a {} board, exposure {:.4g} s; the truth with the {} at {}: {}/capture.json\n",
                 jplate["width"].get<int>(), jplate["height"].get<int>(), o.board, jplate["exposure_s"].get<double>(),
                 o.object, o.object_at, o.out);
    fmt::print("  wrote {}/shoot.json{}\n", o.out, o.truth_size > 0 ? ", truth.exr (the lab's probe at the ball)" : "");
  });
}

void setup(CLI::App& app) {
  app.require_subcommand(1);
  app.footer(
      "Examples:\n  iblkit lab capture low-scene1 --probe 0,1,0 --size 128 --out one\n"
      "  iblkit lab truth low-scene1 --at 0,1,0 --out truth");
  auto* c = app.add_subcommand(
      "capture", "Capture a probe, a probe sequence (iblkit.sequence/1) or a fusion probe set (iblkit.probes/1)");
  auto* co = iblcli::app_owned<CaptureOpts>();
  c->add_option("scene", co->scene,
                "scene file (iblkit.scene/1) or built-in name: low-scene1, low-scene2, t-corridor, crypt")
      ->required();
  c->add_option("--probe", co->probes, "probe position x,y,z (repeat for several)");
  c->add_option("--grid", co->grid, "a regular grid nx,ny,nz over the volume");
  c->add_option("--path", co->path, "a polyline \"x,y,z;x,y,z;…\" with --count probes along it");
  c->add_option("--count", co->count, "probes along --path")->capture_default_str();
  c->add_option("--random", co->random, "N random positions in the volume (tracked hand-held capture)");
  c->add_option("--clusters", co->clusters,
                "with --random N: the N positions in this many Gaussian clusters (a capture at a few spots)")
      ->check(CLI::Range(0, 1000000));
  c->add_option("--cluster-spread", co->cluster_spread, "--clusters: standard deviation of each cluster, metres")
      ->capture_default_str();
  c->add_option("--volume", co->volume, "override the scene's volume: \"x0,y0,z0;x1,y1,z1\"");
  c->add_option("-m,--mapping", co->mapping, "latlong, mirrorball, angular, hcross, vcross, cubestrip, octahedral")
      ->capture_default_str();
  c->add_option("-s,--size", co->size, "lat-long height, cube face edge or disc diameter, pixels")
      ->capture_default_str();
  c->add_option("--samples", co->samples, "n×n sub-pixel samples")->capture_default_str();
  c->add_option("--camera", co->camera, "ideal (mapping directions) or ball (a physical mirror-ball camera)")
      ->capture_default_str();
  c->add_option("--ball-radius", co->ball_radius, "mirror ball radius, metres")->capture_default_str();
  c->add_flag("--parallax", co->parallax, "rays leave the ball's surface (non-single viewpoint)");
  c->add_option("--reflectance", co->reflectance, "mirror ball reflectance")->capture_default_str();
  c->add_option("--look", co->look,
                "world direction of the probe's +Z (a mirror ball's centre; the manifest's rotation)")
      ->capture_default_str();
  c->add_option("--dead-angle", co->dead_angle, "ideal mirror ball: dead angle written to the manifest, degrees")
      ->capture_default_str();
  c->add_flag("--depth", co->depth, "also write depth maps (distance to the first hit, 0 = none)");
  c->add_flag("--fusion", co->fusion, "write a fusion probe set (probes.json, depth maps, proxy.obj)");
  c->add_option("--bounces", co->bounces, "indirect bounces (default: the scene's settings)");
  c->add_option("--area-samples", co->area_samples, "shadow rays per area light per hit (default: the scene's)");
  c->add_option("--env-samples", co->env_samples, "shadow rays towards the environment per hit (default: the scene's)");
  c->add_option("--seed", co->seed, "random seed (default: the scene's)");
  c->add_option("--format", co->format, "frame format: exr, hdr, pfm")->capture_default_str();
  c->add_flag("--half", co->half, ".exr frames as 16-bit halves");
  c->add_option("-o,--out", co->out, "output folder")->required();
  c->footer(
      "Examples:\n  iblkit lab capture low-scene1 --probe 0,1,0 --size 128 --out one\n"
      "  iblkit lab capture low-scene1 --grid 3,3,3 --camera ball --size 64 --out seq\n"
      "  iblkit lab capture t-corridor --path \"0,1.5,9;0,1.5,0.5\" --count 5 --size 64 --out corridor\n"
      "  iblkit lab capture low-scene2 --random 20 --mapping mirrorball --size 64 --out handheld\n"
      "  iblkit lab capture low-scene2 --random 40 --clusters 4 --cluster-spread 0.08 --size 32 --out spots\n"
      "  iblkit lab capture t-corridor --fusion --probe 0,1.5,2 --probe 0,1.5,6 --size 64 --out corridor-fusion");
  c->callback([co] { run_capture(*co); });

  auto* t = app.add_subcommand("truth", "Ground truth at a point: radiance map, SH coefficients, irradiance");
  auto* to = iblcli::app_owned<TruthOpts>();
  t->add_option("scene", to->scene, "scene file or built-in name")->required();
  t->add_option("--at", to->at, "the point x,y,z")->required();
  t->add_option("-s,--size", to->size, "lat-long height of the radiance map")->capture_default_str();
  t->add_option("--samples", to->samples, "n×n sub-pixel samples")->capture_default_str();
  t->add_option("--area-samples", to->area_samples, "shadow rays per area light per hit")->capture_default_str();
  t->add_option("--bands", to->bands, "SH bands (0: none)")->capture_default_str();
  t->add_option("--normal", to->normals, "irradiance normal x,y,z (repeat; default the six axes)");
  t->add_option("--seed", to->seed, "random seed")->capture_default_str();
  t->add_option("--blind-cone", to->blind_cone,
                "also give sh_visible: the SH without the directions within DEG of --blind-axis (a mirror-ball "
                "sequence's dead angle)");
  t->add_option("--blind-axis", to->blind_axis,
                "world axis of --blind-cone (a ball with --look L has its dead angle around -L)")
      ->capture_default_str();
  t->add_option("-o,--out", to->out, "folder for radiance.exr/.png, sh.json, truth.json");
  t->footer("Example:\n  iblkit lab truth low-scene1 --at 0,1,0 --size 64 --out truth");
  t->callback([to] { run_truth(*to); });

  auto* sh = app.add_subcommand("shoot",
                                "Photograph a chrome ball in a scene like a camera: linear radiance, brackets through "
                                "a sensor model, and the lab's probe at the ball's centre");
  auto* so = iblcli::app_owned<ShootOpts>();
  sh->add_option("scene", so->scene, "scene file or built-in name")->required();
  sh->add_option("--at", so->at, "the ball's centre x,y,z")->capture_default_str();
  sh->add_option("--ball-radius", so->ball_radius, "ball radius, metres")->capture_default_str();
  sh->add_option("--distance", so->distance, "camera (pinhole) to ball centre, metres")->capture_default_str();
  sh->add_option("--distance-radii", so->distance_radii, "the same in ball radii (overrides --distance)");
  sh->add_option("--azimuth", so->azimuth, "view 0's camera direction from the ball, degrees about +Y (0: +Z)")
      ->capture_default_str();
  sh->add_option("--elevation", so->elevation, "the camera's height above the ball's horizon, degrees")
      ->capture_default_str();
  sh->add_option("--views", so->views, "the views' turns about +Y from view 0, degrees: \"0\" or \"0,90\"")
      ->capture_default_str();
  sh->add_flag("--two-sides", so->two_sides, "two views 90° apart (--views 0,90)");
  sh->add_option("--width", so->width, "photograph width, pixels")->capture_default_str();
  sh->add_option("--height", so->height, "photograph height, pixels")->capture_default_str();
  sh->add_option("--fill", so->fill, "the ball's diameter over the frame's height")->capture_default_str();
  sh->add_option("--samples", so->samples, "n×n rays per pixel")->capture_default_str();
  sh->add_option("--reflectance", so->reflectance, "normal-incidence reflectance r or r,g,b (default: the metal's)");
  sh->add_option("--fresnel", so->fresnel, "chrome, steel, none or n,k")->capture_default_str();
  sh->add_flag("--no-photographer", so->no_photographer, "leave the camera body and the photographer out");
  sh->add_option("--area-samples", so->area_samples, "shadow rays per area light per hit (default: the scene's)");
  sh->add_option("--bounces", so->bounces, "indirect bounces (default: the scene's)");
  sh->add_option("--truth-size", so->truth_size, "lat-long height of truth.exr, the lab's probe at the ball (0: none)")
      ->capture_default_str();
  sh->add_option("--bracket", so->bracket, "N exposures through the sensor model (0: linear radiance only)")
      ->capture_default_str();
  sh->add_option("--ev-step", so->ev_step, "stops between exposures")->capture_default_str();
  sh->add_flag("--until-unsaturated", so->until_unsaturated,
               "bracket from one step over middle grey down until no pixel saturates (--bracket N: at most N frames)");
  sh->add_option("--exposure", so->exposure,
                 "the middle exposure, seconds (default: the ball's median at middle grey)");
  sh->add_option("--fnumber", so->fnumber, "f-number (EXIF FNumber)")->capture_default_str();
  sh->add_option("--iso", so->iso, "ISO (EXIF ISOSpeedRatings)")->capture_default_str();
  sh->add_option("--response", so->response, "srgb, camera (toe and shoulder) or an iblkit.response/1 file")
      ->capture_default_str();
  sh->add_option("--format", so->format, "jpg (8-bit) or tif (16-bit)")->capture_default_str();
  sh->add_option("--quality", so->quality, "JPEG quality")->check(CLI::Range(1, 100))->capture_default_str();
  sh->add_option("--chroma", so->chroma,
                 "JPEG chroma subsampling: 4:2:0 (libjpeg's and many cameras' default), 4:2:2 or 4:4:4 (none)")
      ->check(CLI::IsMember({"4:2:0", "4:2:2", "4:4:4"}));
  sh->add_flag("--noise", so->noise, "shot and read noise (full well 20000 e⁻ at ISO 100, read noise 0.001)");
  sh->add_option("--full-well", so->full_well, "photo-electrons at saturation at ISO 100 (shot noise)");
  sh->add_option("--read-noise", so->read_noise, "read noise σ in units of saturation");
  sh->add_option("--vignetting", so->vignetting, "v = 1 − vignetting · r² (r over the half-diagonal)")
      ->capture_default_str();
  sh->add_option("--wb", so->wb, "white-balance gains r,g,b")->capture_default_str();
  sh->add_option("--shift", so->shift, "hand-held: frames move by up to this many pixels")->capture_default_str();
  sh->add_option("--seed", so->seed, "random seed")->capture_default_str();
  sh->add_flag("--backplate", so->backplate,
               "also the backplate (a board on the floor), the truth with the object, and capture.json for composite "
               "--capture");
  sh->add_option("--plate-eye", so->plate_eye, "the backplate's camera position")->capture_default_str();
  sh->add_option("--plate-target", so->plate_target, "the point at the backplate's centre")->capture_default_str();
  sh->add_option("--plate-fov", so->plate_fov, "its vertical field of view, degrees")->capture_default_str();
  sh->add_option("--plate-k1", so->plate_k1, "its lens's radial distortion k1 (0: none; writes lens.json)")
      ->capture_default_str();
  sh->add_option("--plate-width", so->plate_width, "backplate width, pixels")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  sh->add_option("--plate-height", so->plate_height, "backplate height, pixels")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  sh->add_option("--plate-samples", so->plate_samples, "n×n rays per backplate pixel")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  sh->add_option("--plate-wb", so->plate_wb, "the backplate's white-balance gains r,g,b")->capture_default_str();
  sh->add_option("--plate-exposure", so->plate_exposure,
                 "the backplate's exposure, seconds (default: its median at middle grey, its highlights kept)");
  sh->add_option("--board", so->board,
                 "the board on the floor: COLSxROWS:SQUARE_M (a checker's inner corners) or a full spec, "
                 "charuco:SQXxSQY:SQUARE_M:MARKER_M[:DICT] (docs/camera.md)")
      ->capture_default_str();
  sh->add_option("--board-at", so->board_at, "the board's centre on the floor x,y,z")->capture_default_str();
  sh->add_option("--object", so->object, "the object of the truth: blob, sphere or a mesh file")->capture_default_str();
  sh->add_option("--object-at", so->object_at, "where its centre goes")->capture_default_str();
  sh->add_option("--object-size", so->object_size, "its largest extent, metres")->capture_default_str();
  sh->add_option("--albedo", so->albedo, "its Lambertian albedo r,g,b")->capture_default_str();
  sh->add_option("-o,--out", so->out, "output folder")->required();
  sh->footer(
      "Examples:\n  iblkit lab shoot low-scene1 --at 0,1,0 --distance-radii 8 --out ball\n"
      "  iblkit lab shoot low-scene2 --two-sides --distance 2 --bracket 5 --ev-step 2 --noise --quality 95 --out "
      "brackets\n"
      "  iblkit lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 384 --height 384 --samples "
      "4 "
      "--bracket 12 --until-unsaturated --ev-step 3 --bounces 1 --noise --wb 1.1,1,0.8 --backplate --out set\n"
      "  iblkit composite --capture set --out set/composite.jpg --layers set/layers");
  sh->callback([so] { run_shoot(*so); });

  auto* ph = app.add_subcommand(
      "photograph",
      "A pinhole photograph of a scene, optionally with an object in it (path traced; the truth of a composite)");
  auto* po = iblcli::app_owned<PhotoOpts>();
  ph->add_option("scene", po->scene, "scene file or built-in name")->required();
  ph->add_option("--eye", po->eye, "camera position x,y,z")->capture_default_str();
  ph->add_option("--target", po->target, "the point seen at the frame's centre")->capture_default_str();
  ph->add_option("--up", po->up, "world direction that appears upwards")->capture_default_str();
  ph->add_option("--fov", po->fov, "vertical field of view, degrees")->capture_default_str();
  ph->add_option("--camera", po->camera,
                 "an iblkit.camera/1 file instead of --eye/--target/--up/--fov (its size, if any, too)");
  ph->add_option("--width", po->width, "frame width, pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  ph->add_option("--height", po->height, "frame height, pixels")->check(CLI::Range(1, 16384))->capture_default_str();
  ph->add_option("--samples", po->samples, "n×n rays per pixel")->check(CLI::Range(1, 64))->capture_default_str();
  ph->add_option("--bounces", po->bounces,
                 "indirect bounces (a probe captured with B bounces sees the light a photograph with B + 1 reflects)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  ph->add_option("--area-samples", po->area_samples, "shadow rays per area light per hit (default: the scene's)");
  ph->add_option("--env-samples", po->env_samples,
                 "shadow rays towards the environment per hit (default: the scene's)");
  ph->add_option("--seed", po->seed, "random seed")->capture_default_str();
  ph->add_option("--object", po->object, "insert an object: blob, sphere, or a mesh file (OBJ, PLY, glTF)");
  ph->add_option("--at", po->at, "where the object's centre goes")->capture_default_str();
  ph->add_option("--object-size", po->object_size,
                 "the object's largest extent, metres (0 keeps a mesh file's size and place)")
      ->capture_default_str();
  ph->add_option("--albedo", po->albedo, "the object's Lambertian albedo r,g,b")->capture_default_str();
  ph->add_option("--triangles", po->triangles, "triangles of the blob")
      ->check(CLI::Range(100, 5000000))
      ->capture_default_str();
  ph->add_option("--mask", po->mask, "also write the object's mask (1 where a pixel centre sees it)");
  ph->add_option("-o,--out", po->out, "output image (.exr)")->required();
  iblcli::outputs(*ph, {"--mask"});  // besides --out (cli.h)
  ph->footer(
      "Example:\n  iblkit lab photograph low-scene2 --eye 0,1.2,2.4 --target 0,0.3,0 --fov 40 --object blob --at "
      "0,0.15,0 "
      "--object-size 0.3 --out truth.exr");
  ph->callback([po] { run_photograph(*po); });
}

iblcli::Command reg("lab", setup);

// Demo: each built-in scene seen from its volume's centre, low-scene1 through the mirror-ball
// camera and as a depth map, and the time one 250×250 mirror-ball probe of low-scene1 takes.
void lab_step(iblcli::DemoContext& ctx) {
  fs::path dir = fs::path(ctx.out_dir) / "lab";
  ibl::make_output_folders(fs::path(dir).string());
  nlohmann::json summary;
  for (const char* name : {"low-scene1", "low-scene2", "t-corridor", "crypt"}) {
    auto scene = ibl::lab::load_scene(name);
    ibl::lab::CaptureDesc cd;
    cd.size = 128;
    cd.samples = 2;
    cd.render = scene.render;
    Vec3 p = (scene.volume_min + scene.volume_max) * 0.5;
    auto cap = ibl::lab::capture_probe(scene, p, cd);
    std::string png = (dir / fmt::format("{}_latlong.png", name)).string();
    ibl::io::write_image(png, ibl::io::tonemap(cap.radiance));
    ctx.pictures.push_back({fmt::format("lab {} lat-long", name), png});
    if (std::string(name) == "low-scene1") {
      ibl::lab::CaptureDesc mb = cd;
      mb.mapping = ibl::sphere::MappingKind::MirrorBall;
      mb.camera = ibl::lab::Camera::MirrorBall;
      mb.size = 250;
      mb.samples = 1;
      mb.depth = true;
      auto t0 = std::chrono::steady_clock::now();
      auto ball = ibl::lab::capture_probe(scene, p, mb);
      summary["mirrorball_250_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::string bpng = (dir / "low-scene1_ball.png").string();
      ibl::io::write_image(bpng, ibl::io::tonemap(ball.radiance));
      ctx.pictures.push_back({"lab low-scene1 mirror-ball camera", bpng});
      ibl::Image depth(ball.depth.width(), ball.depth.height(), 3);
      float dmax = 1e-6f;
      for (size_t i = 0; i < ball.depth.size(); ++i) dmax = std::max(dmax, ball.depth.data()[i]);
      for (int y = 0; y < depth.height(); ++y)
        for (int x = 0; x < depth.width(); ++x) {
          float v = ball.depth.at(x, y, 0) / dmax;
          depth.set_rgb(x, y, {v, v, v});
        }
      std::string dpng = (dir / "low-scene1_depth.png").string();
      ibl::io::write_image(dpng, depth);
      ctx.pictures.push_back({fmt::format("lab low-scene1 depth (white = {:.1f} m)", dmax), dpng});
    }
    auto power = ibl::sphere::EnvMap(cap.radiance, cap.mapping).integral();
    summary[name] = {{"position", {p.x, p.y, p.z}}, {"power_rgb", power}};
  }
  ctx.summary["lab"] = summary;
}

iblcli::DemoStep step("lab", 60, lab_step);

}  // namespace
#endif  // IBLKIT_HAVE_GEOMETRY
