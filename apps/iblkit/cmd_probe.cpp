// iblkit probe from-ball PHOTO.exr [PHOTO2.exr] --out probe.exr: a light probe from linear HDR
// photographs of a chrome ball, unwarped with the real optics (docs/capture.md, "Probes from a chrome
// ball"). Parsing and printing only; capture/ball.h does the work.
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/capture/ball.h"
#include "iblkit/capture/ball_calibrate.h"
#include "iblkit/core/error.h"
#include "iblkit/core/input_file.h"
#include "iblkit/io/image_io.h"

namespace {

struct Opts {
  std::vector<std::string> photos, balls;
  std::string out, weights, mapping = "latlong", reflectance, fresnel = "chrome", angle = "90";
  double distance = 0, focal_mm = 0, sensor_mm = 0, rotate = 0, exclude = 40;
  int size = 256, samples = 2;
  bool orthographic = false, half = false;
};

// The lens: exactly one of --distance, --focal-mm with --sensor-mm, --orthographic.
void check_lens(double distance, double focal_mm, double sensor_mm, bool orthographic) {
  int lenses = (distance > 0) + (focal_mm > 0 || sensor_mm > 0) + orthographic;
  if (lenses != 1)
    ibl::fail(ibl::ErrorKind::Value,
              "give exactly one of --distance (camera to ball centre, in ball radii), --focal-mm with --sensor-mm, "
              "or --orthographic");
}

// One ball photograph: read, its ball given (`ball`, "cx,cy,r") or fitted, its distance from the lens;
// what was found in *jv.
ibl::capture::BallView read_view(const std::string& photo, const std::string& ball, double distance, double focal_mm,
                                 double sensor_mm, bool orthographic, nlohmann::json* jv) {
  ibl::require_input_file(photo, "ball photograph");
  ibl::capture::BallView v;
  v.name = photo;
  v.photo = ibl::io::read_image(photo);
  *jv = {{"photo", photo}, {"width", v.photo.width()}, {"height", v.photo.height()}};
  if (!ball.empty()) {
    auto b = iblcli::parse_double_list(ball, "--ball");
    if (b.size() != 3) ibl::fail(ibl::ErrorKind::Value, "--ball: expected cx,cy,r (pixels), got \"{}\"", ball);
    v.ball = {b[0], b[1], b[2]};
    (*jv)["ball_from"] = "--ball";
  } else {
    ibl::capture::CircleFit f = ibl::capture::find_ball(v.photo, photo, "--ball");
    v.ball = f.circle;
    (*jv)["ball_from"] = "fit";
    (*jv)["fit_residual_px"] = f.residual_px;
    (*jv)["fit_edge_points"] = f.edge_points;
    (*jv)["fit_coverage"] = f.coverage;
  }
  if (distance > 0)
    v.distance = distance;
  else if (!orthographic) {
    if (!(focal_mm > 0 && sensor_mm > 0))
      ibl::fail(ibl::ErrorKind::Value, "--focal-mm and --sensor-mm go together (the sensor's width in mm)");
    v.distance = ibl::capture::distance_from_lens(v.ball.r, v.photo.width(), focal_mm, sensor_mm);
  }
  v.angle_deg = 0;
  (*jv)["ball"] = {v.ball.cx, v.ball.cy, v.ball.r};
  (*jv)["distance_radii"] = v.distance;
  (*jv)["angle_deg"] = v.angle_deg;
  return v;
}

void print_view(const nlohmann::json& jv) {
  fmt::print("{}: ball ({:.2f}, {:.2f}) r {:.2f} px ({}", jv["photo"].get<std::string>(), jv["ball"][0].get<double>(),
             jv["ball"][1].get<double>(), jv["ball"][2].get<double>(), jv["ball_from"].get<std::string>());
  if (jv.contains("fit_residual_px"))
    fmt::print(", residual {:.3f} px, {:.0f} % of the outline", jv["fit_residual_px"].get<double>(),
               100 * jv["fit_coverage"].get<double>());
  double dist = jv["distance_radii"].get<double>();
  fmt::print("), camera at {}\n",
             dist > 0 ? fmt::format("{:.2f} radii", dist) : std::string("infinity (orthographic)"));
}

ibl::Vec3 parse_reflectance(const std::string& s) {
  auto r = iblcli::parse_double_list(s, "--reflectance");
  if (r.size() != 1 && r.size() != 3)
    ibl::fail(ibl::ErrorKind::Value, "--reflectance: expected r or r,g,b, got \"{}\"", s);
  return r.size() == 1 ? ibl::Vec3{r[0], r[0], r[0]} : ibl::Vec3{r[0], r[1], r[2]};
}

void run(const Opts& o) {
  if (o.photos.empty() || o.photos.size() > 2)
    ibl::fail(ibl::ErrorKind::Value, "give one or two ball photographs, got {}", o.photos.size());
  if (!o.balls.empty() && o.balls.size() != o.photos.size())
    ibl::fail(ibl::ErrorKind::Value, "--ball: give one cx,cy,r per photograph ({} photographs, {} --ball)",
              o.photos.size(), o.balls.size());
  check_lens(o.distance, o.focal_mm, o.sensor_mm, o.orthographic);
  ibl::capture::FromBallDesc d;
  d.mapping = ibl::sphere::parse_mapping(o.mapping, "--mapping");
  d.size = o.size;
  d.samples = o.samples;
  d.exclude_deg = o.exclude;
  d.rotation = ibl::Mat3::rotation({0, 1, 0}, o.rotate * ibl::kPi / 180);
  ibl::capture::parse_fresnel(o.fresnel, &d.reflectance);
  if (!o.reflectance.empty()) d.reflectance.r0 = parse_reflectance(o.reflectance);
  std::vector<ibl::capture::BallView> views;
  nlohmann::json jviews = nlohmann::json::array();
  for (size_t i = 0; i < o.photos.size(); ++i) {
    nlohmann::json jv;
    views.push_back(read_view(o.photos[i], o.balls.empty() ? std::string() : o.balls[i], o.distance, o.focal_mm,
                              o.sensor_mm, o.orthographic, &jv));
    jviews.push_back(jv);
  }
  nlohmann::json jangle;
  if (views.size() == 2) {
    if (o.angle == "auto") {
      ibl::capture::AngleEstimate e = ibl::capture::estimate_angle(views, d);
      views[1].angle_deg = e.angle_deg;
      jangle = {{"estimated", true}, {"mean_abs_log_difference", e.residual}, {"directions", e.directions}};
    } else {
      auto a = iblcli::parse_double_list(o.angle, "--angle");
      if (a.size() != 1) ibl::fail(ibl::ErrorKind::Value, "--angle: expected degrees or auto, got \"{}\"", o.angle);
      views[1].angle_deg = a[0];
      jangle = {{"estimated", false}};
    }
    jangle["angle_deg"] = views[1].angle_deg;
    jviews[1]["angle_deg"] = views[1].angle_deg;
  }
  ibl::capture::FromBallResult r = ibl::capture::probe_from_ball(views, d);
  ibl::io::write_image(o.out, r.probe.image, {o.half});
  if (!o.weights.empty()) ibl::io::write_image(o.weights, r.weights);
  nlohmann::json j = {{"out", o.out},
                      {"mapping", ibl::sphere::mapping_name(d.mapping)},
                      {"width", r.probe.image.width()},
                      {"height", r.probe.image.height()},
                      {"views", jviews},
                      {"blind_cone_deg", r.blind_cone_deg},
                      {"invalid_pixels", r.invalid_pixels}};
  if (!o.weights.empty()) j["weights"] = o.weights;
  if (!jangle.is_null()) j["angle"] = jangle;
  iblcli::emit(j, [&] {
    for (const auto& jv : jviews) print_view(jv);
    if (!jangle.is_null() && jangle["estimated"].get<bool>())
      fmt::print(
          "second view at {:.2f}° (estimated from the overlap: mean |log difference| {:.3f} over {} directions)\n",
          jangle["angle_deg"].get<double>(), jangle["mean_abs_log_difference"].get<double>(),
          jangle["directions"].get<int>());
    fmt::print("wrote {} ({} {}x{}, RGBA: alpha 0 where no view sees)", o.out, ibl::sphere::mapping_name(d.mapping),
               r.probe.image.width(), r.probe.image.height());
    if (views.size() == 1 && r.blind_cone_deg > 0) fmt::print("; blind cone {:.2f}° around −Z", r.blind_cone_deg);
    fmt::print(", {} invalid pixels\n", r.invalid_pixels);
    if (!o.weights.empty()) fmt::print("  blend weights (the first photograph's share): {}\n", o.weights);
  });
}

// The ball camera's lens: --distance, or --focal-mm with --sensor-mm, or --orthographic (check_lens).
void add_lens_options(CLI::App* c, double* distance, double* focal_mm, double* sensor_mm, bool* orthographic) {
  c->add_option("--distance", *distance, "camera to ball centre, in ball radii (> 1)");
  c->add_option("--focal-mm", *focal_mm, "lens focal length, mm (with --sensor-mm: the distance from the ball's size)");
  c->add_option("--sensor-mm", *sensor_mm, "sensor width, mm");
  c->add_flag("--orthographic", *orthographic, "the orthographic approximation (a camera infinitely far)");
}

struct CalOpts {
  std::string photo, ball, direct, in_ball, in_direct, fresnel = "chrome";
  double distance = 0, focal_mm = 0, sensor_mm = 0, plateau = 0.8;
  bool orthographic = false;
};

ibl::capture::PixelBox parse_box(const std::string& s, const char* what) {
  auto v = iblcli::parse_double_list(s, what);
  if (v.size() != 4) ibl::fail(ibl::ErrorKind::Value, "{}: expected x,y,w,h (pixels), got \"{}\"", what, s);
  return {v[0], v[1], v[2], v[3]};
}

void run_calibrate(const CalOpts& o) {
  check_lens(o.distance, o.focal_mm, o.sensor_mm, o.orthographic);
  ibl::capture::BallReflectance metal;
  ibl::capture::parse_fresnel(o.fresnel, &metal);
  nlohmann::json jv;
  ibl::capture::BallView v = read_view(o.photo, o.ball, o.distance, o.focal_mm, o.sensor_mm, o.orthographic, &jv);
  ibl::require_input_file(o.direct, "the light's photograph (--direct)");
  ibl::Image direct = ibl::io::read_image(o.direct);
  ibl::capture::ReflectanceFit f =
      ibl::capture::calibrate_reflectance(v, metal, parse_box(o.in_ball, "--light-in-ball"), direct,
                                          parse_box(o.in_direct, "--light"), o.plateau, "--light-in-ball/--light");
  nlohmann::json j = {{"view", jv},
                      {"direct", o.direct},
                      {"reflectance", {f.r0.x, f.r0.y, f.r0.z}},
                      {"light", {f.light.x, f.light.y, f.light.z}},
                      {"fresnel", o.fresnel},
                      {"incidence_deg", {f.incidence_min_deg, f.incidence_max_deg}},
                      {"ball_pixels", f.ball_pixels},
                      {"direct_pixels", f.direct_pixels},
                      {"spread", f.spread}};
  iblcli::emit(j, [&] {
    print_view(jv);
    fmt::print("light     {:.4g},{:.4g},{:.4g} over {} pixels of {}\n", f.light.x, f.light.y, f.light.z,
               f.direct_pixels, o.direct);
    fmt::print("reflection over {} ball pixels at {:.1f}–{:.1f}° incidence ({} rise taken out), spread {:.3f}\n",
               f.ball_pixels, f.incidence_min_deg, f.incidence_max_deg, o.fresnel, f.spread);
    fmt::print(
        "reflectance {:.4f},{:.4f},{:.4f} at normal incidence: probe from-ball --reflectance {:.4f},{:.4f},{:.4f}"
        " --fresnel {}\n",
        f.r0.x, f.r0.y, f.r0.z, f.r0.x, f.r0.y, f.r0.z, o.fresnel);
  });
}

void setup_calibrate(CLI::App& app) {
  auto* o = iblcli::app_owned<CalOpts>();
  auto* c = app.add_subcommand("calibrate",
                               "The ball's reflectance from a light seen both in the ball and directly (the same "
                               "camera and exposure: a window, a softbox, a panel)");
  c->add_option("photo", o->photo, "the ball's linear HDR photograph (.exr .hdr .pfm)")->required();
  c->add_option("--ball", o->ball, "the silhouette cx,cy,r (pixels, continuous coordinates; default: fitted)");
  add_lens_options(c, &o->distance, &o->focal_mm, &o->sensor_mm, &o->orthographic);
  c->add_option("--light-in-ball", o->in_ball,
                "x,y,w,h: a box around the light's reflection in the ball photograph (pixels)")
      ->required();
  c->add_option("--direct", o->direct,
                "a linear image of the light itself in the same units (the same camera and exposure, merged as the "
                "ball's)")
      ->required();
  c->add_option("--light", o->in_direct, "x,y,w,h: a box around the light in --direct (pixels)")->required();
  c->add_option("--fresnel", o->fresnel, "the ball's rise towards grazing, taken out: chrome, steel, none or n,k")
      ->capture_default_str();
  c->add_option("--plateau", o->plateau,
                "the light's pixels: at least this share of each box's 95th-percentile luminance")
      ->capture_default_str();
  c->footer(
      "Example:\n  iblkit probe calibrate window/view0.exr --distance 8 --light-in-ball 200,105,25,45 --direct "
      "window/light.exr --light 15,12,35,40\n"
      "Prints the reflectance to give probe from-ball (--reflectance r,g,b).");
  c->callback([o] { run_calibrate(*o); });
}

void setup(CLI::App& app) {
  app.require_subcommand(1);
  auto* c = app.add_subcommand("from-ball", "A probe from one or two linear HDR photographs of a chrome ball");
  auto* o = iblcli::app_owned<Opts>();
  c->add_option("photos", o->photos, "one photograph, or two taken about 90° apart (linear HDR: .exr .hdr .pfm)")
      ->required()
      ->expected(1, 2);
  c->add_option("--ball", o->balls,
                "the ball's silhouette cx,cy,r in pixels (continuous: the image spans [0,W]×[0,H]); once per "
                "photograph; default: found by a circle fit to its edge");
  add_lens_options(c, &o->distance, &o->focal_mm, &o->sensor_mm, &o->orthographic);
  c->add_option("--reflectance", o->reflectance,
                "the ball's normal-incidence reflectance, r or r,g,b (default: the metal's own)");
  c->add_option("--fresnel", o->fresnel, "the rise towards grazing: chrome, steel, none or n,k")->capture_default_str();
  c->add_option("--angle", o->angle,
                "two views: where the second camera stood, degrees about +Y from the first (+90: to the first "
                "view's +X, the photographer walked to their right), or auto (estimated from the overlap in "
                "[45, 135])")
      ->capture_default_str();
  c->add_option("--exclude", o->exclude,
                "two views: directions within this many degrees of a view's camera axis come from the other view")
      ->capture_default_str();
  c->add_option("--rotate", o->rotate, "turn the probe about +Y by this many degrees (to set north)")
      ->capture_default_str();
  c->add_option("-m,--mapping", o->mapping, "latlong, mirrorball, angular, hcross, vcross, cubestrip, octahedral")
      ->capture_default_str();
  c->add_option("-s,--size", o->size, "lat-long height, cube face edge or disc diameter, pixels")
      ->capture_default_str()
      ->check(CLI::Range(1, 16384));
  c->add_option("--samples", o->samples, "n×n sub-samples per output pixel")->capture_default_str();
  c->add_option("-o,--out", o->out, "the probe (RGBA .exr)")->required();
  c->add_option("--weights", o->weights,
                "write the blend weights (the first photograph's share of each pixel) as an image");
  c->add_flag("--half", o->half, "write .exr as 16-bit half floats");
  iblcli::outputs(*c, {"--weights"});
  c->footer(
      "Examples:\n  iblkit probe from-ball ball/view0.exr --distance 8 --out probe.exr\n"
      "  iblkit probe from-ball brackets/view0.exr brackets/view1.exr --ball 256,256,230.4 --ball 256,256,230.4 "
      "--distance 40 --angle 90 --weights w.exr --out probe2.exr");
  c->callback([o] { run(*o); });
  setup_calibrate(app);
}

iblcli::Command reg("probe", setup);

}  // namespace
