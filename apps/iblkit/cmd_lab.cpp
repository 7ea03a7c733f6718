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
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/capture.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
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
