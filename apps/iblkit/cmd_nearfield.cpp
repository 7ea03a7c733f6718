// iblkit nearfield simulate|info|render|irradiance|fig3: measured (or lab-simulated) luminaire light
// fields as textured spotlights (Granier et al. 2003), against the lab luminaire's exact answer and
// the far-field approximation. Guide: docs/nearfield.md.
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/nearfield/basis.h"
#include "iblkit/nearfield/luminaire.h"
#include "iblkit/nearfield/reconstruct.h"
#include "iblkit/nearfield/render.h"
#include "iblkit/nearfield/scene_render.h"

namespace {

namespace fs = std::filesystem;
namespace nf = ibl::nearfield;
using ibl::Image;
using ibl::Vec3;
using nlohmann::json;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

json stats_json(const nf::ErrorStats& s) {
  return {
      {"rel_rms", s.rel_rms}, {"rel_mean_abs", s.rel_mean_abs}, {"rel_max", s.rel_max}, {"power_ratio", s.power_ratio}};
}

// Tone maps a set of images with one exposure: the first image's 99th-percentile luminance lands on
// 2 (ACES keeps detail there; the median of a spotlit scene is black, so auto exposure would not do).
std::vector<Image> same_exposure(const std::vector<Image>& imgs) {
  std::vector<double> lum;
  const Image& ref = imgs.front();
  for (int y = 0; y < ref.height(); ++y)
    for (int x = 0; x < ref.width(); ++x) lum.push_back(ibl::luminance(ref.rgb(x, y)));
  std::sort(lum.begin(), lum.end());
  const double p99 = lum.empty() ? 1.0 : std::max(lum[lum.size() * 99 / 100], 1e-30);
  ibl::io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(2.0 / p99);
  std::vector<Image> out;
  for (const auto& i : imgs) out.push_back(ibl::io::tonemap(i, td));
  return out;
}

std::pair<int, int> parse_grid(const std::string& s) {
  int a = 0, b = 0;
  char x = 0;
  if (std::sscanf(s.c_str(), "%d%c%d", &a, &x, &b) != 3 || (x != 'x' && x != 'X'))
    ibl::fail(ibl::ErrorKind::Value, "--grid '{}': expected NXxNY, e.g. 9x7", s);
  return {a, b};
}

// Figure 3 of Granier et al.: E_r(θ0) for several relative filter widths s.
Image fig3_plot(bool two_d) {
  const int W = 560, H = 360, x0 = 60, y0 = 320, pw = 470, ph = 290;
  Image img(W, H, 3, 1.0f);
  const double ymax = 0.4, tmax = 80;
  auto X = [&](double deg) { return x0 + deg / tmax * pw; };
  auto Y = [&](double e) { return y0 - std::min(e, ymax) / ymax * ph; };
  Vec3 grey{0.8, 0.8, 0.8}, black{0, 0, 0};
  for (double e = 0; e <= ymax + 1e-9; e += 0.05) {
    ibl::io::draw_line(img, x0, Y(e), x0 + pw, Y(e), grey);
    ibl::io::draw_text(img, 8, static_cast<int>(Y(e)) + 5, fmt::format("{:.0f}%", e * 100), 13, black);
  }
  for (double t = 0; t <= tmax; t += 10) {
    ibl::io::draw_line(img, X(t), y0, X(t), y0 - ph, grey);
    ibl::io::draw_text(img, static_cast<int>(X(t)) - 8, y0 + 18, fmt::format("{:.0f}", t), 13, black);
  }
  ibl::io::draw_text(img, x0 + pw / 2 - 40, y0 + 36, "theta0 (degrees)", 13, black);
  ibl::io::draw_text(img, x0 + 10, 22, two_d ? "E_r(theta0), 2-D square support" : "E_r(theta0), Granier et al. Fig. 3",
                     15, black);
  const double widths[] = {0.01, 0.02, 0.04, 0.08};
  const Vec3 cols[] = {{0.1, 0.4, 0.9}, {0.1, 0.7, 0.2}, {0.9, 0.3, 0.1}, {0.6, 0.1, 0.7}};
  for (int k = 0; k < 4; ++k) {
    double px = X(0), py = Y(nf::shift_invariance_error(0, widths[k], two_d));
    for (double t = 0.5; t <= tmax; t += 0.5) {
      double e = nf::shift_invariance_error(t * ibl::kPi / 180, widths[k], two_d);
      ibl::io::draw_line(img, px, py, X(t), Y(e), cols[k], 2.0);
      px = X(t);
      py = Y(e);
    }
    ibl::io::draw_text(img, x0 + 20, 50 + 18 * k, fmt::format("s = {:.2f}", widths[k]), 14, cols[k]);
  }
  return img;
}

// ---- simulate -------------------------------------------------------------------------------
struct SimOpts {
  std::string luminaire = "flashlight", grid = "7x7", basis = "biquadratic", out;
  double spacing = 0.005, distance = 0.5, extent = 0;
  int resolution = 128;
};

void run_simulate(const SimOpts& o) {
  auto lum = nf::make_luminaire(o.luminaire);
  nf::SimulateDesc d;
  std::tie(d.nx, d.ny) = parse_grid(o.grid);
  d.basis = nf::parse_basis(o.basis, "--basis");
  d.spacing = o.spacing;
  d.distance = o.distance;
  d.resolution = o.resolution;
  d.extent = o.extent;
  const auto half = lum.half_size();
  // Where the B-splines Φ_mn add up to 1 on S (the grid's full-reconstruction region), per axis.
  const double trim = nf::primal_half_width(d.basis) - 1;
  const double pou_x = (0.5 * (d.nx - 1) - trim) * d.spacing, pou_y = (0.5 * (d.ny - 1) - trim) * d.spacing;
  auto t0 = std::chrono::steady_clock::now();
  auto ds = nf::simulate(lum, d, iblcli::progress_bar());
  iblcli::progress_done();
  double secs = seconds_since(t0);
  if (o.out.empty()) ibl::fail(ibl::ErrorKind::Value, "--out MANIFEST.json is required");
  nf::write_dataset(o.out, ds);
  json j = {{"manifest", o.out},
            {"name", ds.name},
            {"luminaire", lum.name},
            {"grid", {ds.nx, ds.ny}},
            {"basis", nf::basis_name(ds.basis)},
            {"spacing", ds.spacing},
            {"filter_width", ds.filter_width},
            {"distance", ds.distance},
            {"extent", ds.m_max.x},
            {"resolution", d.resolution},
            {"seconds", secs},
            {"luminaire_half_size", {half.x, half.y}},
            {"full_reconstruction_half_size", {pou_x, pou_y}}};
  iblcli::emit(j, [&] {
    fmt::print(
        "simulated {} ({} filter positions, {} dual filter {:.1f} mm wide, h = {:.1f} mm, d = {:.2f} m) in {:.2f} s\n",
        ds.name, ds.count(), nf::basis_name(ds.basis), ds.filter_width * 1e3, ds.spacing * 1e3, ds.distance, secs);
    fmt::print("  images {}x{} over ±{:.3f} m on M\n  manifest: {}\n", d.resolution, d.resolution, ds.m_max.x, o.out);
    if (half.x > pou_x || half.y > pou_y)
      fmt::print(
          "  note: the luminaire ({:.1f} x {:.1f} mm half size) reaches beyond the grid's full-reconstruction region "
          "(±{:.1f} x ±{:.1f} mm)\n",
          half.x * 1e3, half.y * 1e3, pou_x * 1e3, pou_y * 1e3);
  });
}

// ---- info -----------------------------------------------------------------------------------
void run_info(const std::string& path) {
  auto ds = nf::read_dataset(path);
  auto ep = nf::incoming_radiance(ds);
  double neg = 0, pos = 0;
  for (const auto& e : ep)
    for (size_t k = 0; k < e.size(); ++k) (e.data()[k] < 0 ? neg : pos) += std::abs(e.data()[k]);
  const double s = nf::primal_half_width(ds.basis) * 2 * ds.spacing / ds.distance;
  double worst = 0;
  for (double t = 0; t < 1.4; t += 0.002) worst = std::max(worst, nf::shift_invariance_error(t, s, true));
  // Power through M: Σ_mn E_mn integrated over M (the open-aperture irradiance, by the partition of unity).
  Vec3 power{0, 0, 0};
  const int W = ds.positive[0].width(), H = ds.positive[0].height();
  const double px = (ds.m_max.x - ds.m_min.x) * (ds.m_max.y - ds.m_min.y) / (static_cast<double>(W) * H);
  for (int j = 0; j < ds.ny; ++j)
    for (int i = 0; i < ds.nx; ++i) {
      Image m = ds.measurement(i, j);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) power += m.rgb(x, y) * px;
    }
  json j = {{"manifest", path},
            {"name", ds.name},
            {"luminaire", ds.luminaire},
            {"grid", {ds.nx, ds.ny}},
            {"basis", nf::basis_name(ds.basis)},
            {"m_basis", nf::basis_name(ds.m_basis)},
            {"spacing", ds.spacing},
            {"filter_width", ds.filter_width},
            {"distance", ds.distance},
            {"m_extent", {{"min", {ds.m_min.x, ds.m_min.y}}, {"max", {ds.m_max.x, ds.m_max.y}}}},
            {"image_size", {W, H}},
            {"power_through_m", {power.x, power.y, power.z}},
            {"negative_texel_fraction", neg / std::max(pos + neg, 1e-300)},
            {"relative_support_width", s},
            {"worst_shift_invariance_error_2d", worst}};
  iblcli::emit(j, [&] {
    fmt::print("{}: {} ({}x{} filter positions{})\n", path, ds.name, ds.nx, ds.ny,
               ds.luminaire.empty() ? "" : ", lab luminaire " + ds.luminaire);
    fmt::print("  basis {} (dual filter {:.1f} mm), spacing {:.2f} mm, planes {:.3f} m apart, M basis {}\n",
               nf::basis_name(ds.basis), ds.filter_width * 1e3, ds.spacing * 1e3, ds.distance,
               nf::basis_name(ds.m_basis));
    fmt::print("  images {}x{} over [{:.3f}, {:.3f}] x [{:.3f}, {:.3f}] m\n", W, H, ds.m_min.x, ds.m_max.x, ds.m_min.y,
               ds.m_max.y);
    fmt::print("  power through M: ({:.4g}, {:.4g}, {:.4g}) W\n", power.x, power.y, power.z);
    fmt::print("  E' textures: {:.1f}% of |texel| mass negative (dual filter lobes)\n",
               100 * neg / std::max(pos + neg, 1e-300));
    fmt::print("  Φ support / d = {:.4f}: shift-invariance error E_r up to {:.1f}% (2-D support, θ0 < 80°)\n", s,
               100 * worst);
  });
}

// ---- render / irradiance ----------------------------------------------------------------------
struct LightOpts {
  std::string at = "-0.55,0.45,-0.75", aim = "-1.3,0.25,-1.6", up = "0,1,0";
  std::string exact;  // lab luminaire to compare with ("auto": the dataset's own)
  bool no_far = false;
};

nf::Placement placement_of(const LightOpts& o) {
  nf::Placement p;
  p.position = iblcli::parse_vec3(o.at, "--at");
  p.forward = iblcli::parse_vec3(o.aim, "--aim") - p.position;
  p.up_hint = iblcli::parse_vec3(o.up, "--up");
  p.frame();  // validates
  return p;
}

struct RenderOpts {
  std::string dataset, scene = "crypt", out, eye = "0.9,1.5,0.9", target = "-1.1,0.3,-1.5", ies;
  int size = 400;
  double fov = 55, ies_scale = 1;
  bool no_shadows = false, srgbe = false;
  LightOpts light;
};

void run_render(const RenderOpts& o) {
  if (o.out.empty()) ibl::fail(ibl::ErrorKind::Value, "--out VIEW.png is required");
  auto scene = ibl::lab::load_scene(o.scene);
  nf::SceneView sv(ibl::lab::diffuse_surfaces(scene), scene.name);
  nf::SceneRenderDesc d;
  d.dataset = o.dataset;
  d.ies = o.ies;
  d.ies_scale = o.ies_scale;
  d.exact = o.light.exact;
  d.far_field = !o.light.no_far;
  d.camera.eye = iblcli::parse_vec3(o.eye, "--eye");
  d.camera.target = iblcli::parse_vec3(o.target, "--target");
  d.camera.width = d.camera.height = o.size;
  d.camera.fov_y_deg = o.fov;
  d.placement = placement_of(o.light);
  d.shadows = !o.no_shadows;
  d.srgbe = o.srgbe;
  const nf::SceneRender r = nf::render_scene(sv, d, iblcli::progress_bar());
  iblcli::progress_done();
  const std::string& label = r.label;
  json j = {{"dataset", label},
            {"scene", scene.name},
            {"out", o.out},
            {"size", o.size},
            {"spotlights", r.spotlights},
            {"shadows", !o.no_shadows},
            {"setup_seconds", r.setup_seconds},
            {"render_seconds", r.render_seconds}};
  if (r.srgbe_error)
    j["srgbe_passes"] = {{"passes", r.srgbe_passes},
                         {"error_vs_float", stats_json(*r.srgbe_error)},
                         {"frame_buffer_bytes_float", 12 * o.size * o.size},
                         {"frame_buffer_bytes_srgbe", 4 * o.size * o.size}};
  std::vector<Image> imgs{r.near_field};
  std::vector<std::string> names{"near-field (Eq. 14)"};
  if (r.exact) {
    j["exact_seconds"] = r.exact_seconds;
    j["near_field_error"] = stats_json(*r.near_field_error);
    imgs.insert(imgs.begin(), *r.exact);
    names.insert(names.begin(), "exact (virtual luminaire)");
  }
  if (r.far_field) {
    j["far_field_error"] = stats_json(*r.far_field_error);
    imgs.push_back(*r.far_field);
    names.push_back("far field (1 goniometric point)");
  }
  auto tm = same_exposure(imgs);
  std::string base = o.out.substr(0, o.out.size() - fs::path(o.out).extension().string().size());
  if (fs::path(o.out).extension() == ".exr") {
    ibl::io::write_image(o.out, imgs.size() > 1 ? imgs[1] : imgs[0]);
  } else {
    ibl::io::write_image(o.out, tm.size() > 1 ? tm[1] : tm[0]);
  }
  if (imgs.size() > 1) {
    std::vector<std::pair<std::string, Image>> pics;
    for (size_t k = 0; k < tm.size(); ++k) pics.push_back({names[k], tm[k]});
    std::string sheet = base + "_compare.png";
    ibl::io::write_image(sheet, ibl::io::contact_sheet(pics, static_cast<int>(pics.size()), o.size, o.size,
                                                       label + " in " + scene.name));
    j["comparison"] = sheet;
  }
  iblcli::emit(j, [&] {
    fmt::print("rendered {} in {} at {}x{} with {} spotlight{}{}: {:.2f} s (+{:.2f} s reading and E' textures)\n",
               label, scene.name, o.size, o.size, r.spotlights, r.spotlights == 1 ? "" : "s",
               o.no_shadows ? "" : " and shadow rays", r.render_seconds, r.setup_seconds);
    fmt::print("  wrote {}\n", o.out);
    if (j.contains("near_field_error")) {
      auto& a = j["near_field_error"];
      fmt::print(
          "  near field vs exact: RMS {:.1f}%, mean |Δ| {:.1f}% of the mean, max {:.1f}% of the max, power ×{:.3f}\n",
          100 * a["rel_rms"].get<double>(), 100 * a["rel_mean_abs"].get<double>(), 100 * a["rel_max"].get<double>(),
          a["power_ratio"].get<double>());
    }
    if (j.contains("far_field_error")) {
      auto& a = j["far_field_error"];
      fmt::print(
          "  far field  vs exact: RMS {:.1f}%, mean |Δ| {:.1f}% of the mean, max {:.1f}% of the max, power ×{:.3f}\n",
          100 * a["rel_rms"].get<double>(), 100 * a["rel_mean_abs"].get<double>(), 100 * a["rel_max"].get<double>(),
          a["power_ratio"].get<double>());
    }
    if (j.contains("srgbe_passes")) {
      auto& a = j["srgbe_passes"]["error_vs_float"];
      fmt::print(
          "  sRGBE frame buffer ({} passes of 3, 4 instead of 12 bytes a pixel): RMS {:.3f}%, max {:.3f}% of the max "
          "vs float\n",
          j["srgbe_passes"]["passes"].get<int>(), 100 * a["rel_rms"].get<double>(), 100 * a["rel_max"].get<double>());
    }
    if (j.contains("comparison")) fmt::print("  side by side: {}\n", j["comparison"].get<std::string>());
  });
}

struct IrrOpts {
  std::string dataset, plane = "z=0.5", out, exact = "auto";
  int size = 128;
  double extent = 0;
};

void run_irradiance(const IrrOpts& o) {
  if (o.plane.rfind("z=", 0) != 0)
    ibl::fail(ibl::ErrorKind::Value, "--plane '{}': expected z=DISTANCE (metres from S along the beam)", o.plane);
  double z = 0;
  try {
    z = std::stod(o.plane.substr(2));
  } catch (const std::exception&) {
    ibl::fail(ibl::ErrorKind::Value, "--plane '{}': '{}' is not a number", o.plane, o.plane.substr(2));
  }
  if (o.out.empty()) ibl::fail(ibl::ErrorKind::Value, "--out IRR.exr is required");
  auto ds = nf::read_dataset(o.dataset);
  nf::Placement pl;
  pl.position = {0, 0, 0};
  nf::PlaneDesc pd;
  pd.z = z;
  pd.resolution = o.size;
  // Default extent: where the dataset's own rays reach at z (M's extent scaled by z/d).
  pd.half_extent = o.extent > 0 ? o.extent : std::max(std::abs(ds.m_min.x), ds.m_max.x) * z / ds.distance;
  auto lights = nf::spotlights(ds, pl, false);
  Image nfi = nf::plane_irradiance(lights, pl, pd);
  ibl::io::write_image(o.out, nfi);
  json j = {{"dataset", ds.name}, {"z", z}, {"half_extent", pd.half_extent}, {"out", o.out}};
  Vec3 mean{0, 0, 0};
  for (int y = 0; y < nfi.height(); ++y)
    for (int x = 0; x < nfi.width(); ++x) mean += nfi.rgb(x, y) * (1.0 / nfi.pixel_count());
  j["mean_irradiance"] = {mean.x, mean.y, mean.z};
  auto lum = nf::exact_luminaire(ds, ds.luminaire.empty() && o.exact == "auto" ? "none" : o.exact);
  std::string base = o.out.substr(0, o.out.size() - fs::path(o.out).extension().string().size());
  if (lum) {
    Image ex = nf::plane_irradiance_exact(*lum, pd);
    auto ff = nf::far_field_spotlight([&](Vec3 w) { return lum->intensity(w); }, ds.distance, ds.m_max.x,
                                      ds.positive[0].width(), pl);
    Image fi = nf::plane_irradiance({ff}, pl, pd);
    j["near_field_error"] = stats_json(nf::compare(nfi, ex));
    j["far_field_error"] = stats_json(nf::compare(fi, ex));
    ibl::io::write_image(base + "_exact.exr", ex);
    auto tm = same_exposure({ex, nfi, fi});
    ibl::io::write_image(base + "_compare.png",
                         ibl::io::contact_sheet({{"exact", tm[0]}, {"near field", tm[1]}, {"far field", tm[2]}}, 3, 256,
                                                256, fmt::format("{} at z = {} m", ds.name, z)));
    j["comparison"] = base + "_compare.png";
  }
  iblcli::emit(j, [&] {
    fmt::print(
        "irradiance of {} on the plane z = {} m (±{:.3f} m, {}²): mean ({:.4g}, {:.4g}, {:.4g}) W/m²\n  wrote {}\n",
        ds.name, z, pd.half_extent, o.size, mean.x, mean.y, mean.z, o.out);
    for (const char* k : {"near_field_error", "far_field_error"})
      if (j.contains(k))
        fmt::print("  {:<16} vs exact: RMS {:.2f}%, max {:.2f}% of the max, power ×{:.4f}\n", k,
                   100 * j[k]["rel_rms"].get<double>(), 100 * j[k]["rel_max"].get<double>(),
                   j[k]["power_ratio"].get<double>());
    if (j.contains("comparison")) fmt::print("  side by side: {}\n", j["comparison"].get<std::string>());
  });
}

void setup(CLI::App& app) {
  app.require_subcommand(1);
  app.footer(
      "Examples:\n  iblkit nearfield simulate flashlight --grid 3x3 --resolution 16 --out nf/nf.json\n"
      "  iblkit nearfield render nf/nf.json --out nf.png");
  auto* so = iblcli::app_owned<SimOpts>();
  auto* s = app.add_subcommand(
      "simulate", "Simulate the acquisition of a lab luminaire: a dataset of filter positions (iblkit.nearfield/1)");
  s->add_option("luminaire", so->luminaire, "flashlight or bikelight")->capture_default_str();
  s->add_option("--grid", so->grid, "filter positions NXxNY")->capture_default_str();
  s->add_option("--basis", so->basis, "bilinear or biquadratic (the filter is its dual)")->capture_default_str();
  s->add_option("--spacing", so->spacing, "filter spacing h on S (metres)")->capture_default_str();
  s->add_option("--distance", so->distance, "distance d between S and M (metres)")->capture_default_str();
  s->add_option("--resolution", so->resolution, "image size on M (pixels per side)")->capture_default_str();
  s->add_option("--extent", so->extent, "half-extent of M (metres); 0 = what the luminaire's cut-off reaches")
      ->capture_default_str();
  s->add_option("-o,--out", so->out, "manifest path STEM.json (images go to STEM_images/ beside it)")->required();
  s->footer(
      "Examples:\n  iblkit nearfield simulate bikelight --grid 9x7 --out bike/bike.json\n"
      "  iblkit nearfield simulate flashlight --grid 5x5 --spacing 0.0075 --out mag5/mag5.json");
  s->callback([so] { run_simulate(*so); });

  auto* path = iblcli::app_owned<std::string>();
  auto* i = app.add_subcommand("info", "Summary of a near-field dataset: grid, basis, power, shift-invariance error");
  i->add_option("dataset", *path, "iblkit.nearfield/1 manifest")->required();
  i->footer("Example:\n  iblkit nearfield info bike/bike.json");
  i->callback([path] { run_info(*path); });

  auto* ro = iblcli::app_owned<RenderOpts>();
  auto* r = app.add_subcommand(
      "render", "Render a lab scene lit by the dataset's textured spotlights (CPU reference, shadow rays)");
  r->add_option("dataset", ro->dataset, "iblkit.nearfield/1 manifest");
  r->add_option("--ies", ro->ies, "render an IES LM-63 file instead (one far-field spotlight)");
  r->add_option("--ies-scale", ro->ies_scale, "multiplies the IES candela values")->capture_default_str();
  r->add_option("--scene", ro->scene, "lab scene name or file")->capture_default_str();
  r->add_option("-o,--out", ro->out, "picture (.png tone mapped, .exr radiance)")->required();
  r->add_option("--size", ro->size, "pixels per side")->capture_default_str();
  r->add_option("--eye", ro->eye, "camera position x,y,z")->capture_default_str();
  r->add_option("--target", ro->target, "camera target x,y,z")->capture_default_str();
  r->add_option("--fov", ro->fov, "vertical field of view (degrees)")->capture_default_str();
  r->add_option("--at", ro->light.at, "luminaire position (centre of S) x,y,z")->capture_default_str();
  r->add_option("--aim", ro->light.aim, "point the luminaire shines at x,y,z")->capture_default_str();
  r->add_option("--exact", ro->light.exact,
                "also render the lab luminaire exactly (NAME or auto) and the far field, with errors");
  r->add_flag("--no-far", ro->light.no_far, "with --exact: skip the far-field picture");
  r->add_flag("--no-shadows", ro->no_shadows, "no visibility tests");
  r->add_flag("--srgbe", ro->srgbe,
              "also sum through the paper's sRGBE frame buffer (passes of 3) and report its error");
  r->footer(
      "Examples:\n  iblkit nearfield render bike/bike.json --scene crypt --out view.png\n"
      "  iblkit nearfield render bike/bike.json --scene crypt --exact auto --size 200 --out view.png");
  r->callback([ro] {
    if (ro->dataset.empty() == ro->ies.empty())
      ibl::fail(ibl::ErrorKind::Value, "give a DATASET or --ies FILE (one of them)");
    run_render(*ro);
  });

  auto* io = iblcli::app_owned<IrrOpts>();
  auto* ir = app.add_subcommand(
      "irradiance", "Irradiance on a receiver plane facing the luminaire (vs the exact answer for lab datasets)");
  ir->add_option("dataset", io->dataset, "iblkit.nearfield/1 manifest")->required();
  ir->add_option("--plane", io->plane, "z=DISTANCE from S along the beam (metres)")->capture_default_str();
  ir->add_option("-o,--out", io->out, "irradiance image (.exr)")->required();
  ir->add_option("--size", io->size, "pixels per side")->capture_default_str();
  ir->add_option("--extent", io->extent, "half-extent of the plane (metres); 0 = the dataset's reach at that distance");
  ir->add_option("--exact", io->exact, "compare with this lab luminaire (auto: the dataset's own; none)")
      ->capture_default_str();
  ir->footer("Example:\n  iblkit nearfield irradiance bike/bike.json --plane z=0.25 --out irr.exr");
  ir->callback([io] { run_irradiance(*io); });

  auto* fo = iblcli::app_owned<std::string>();
  auto* f = app.add_subcommand("fig3", "Plot the shift-invariance error E_r(θ0) (Granier et al. Fig. 3)");
  f->add_option("-o,--out", *fo, "picture (.png); a _2d.png with the 2-D support is written beside it")->required();
  f->footer("Example:\n  iblkit nearfield fig3 --out fig3.png");
  f->callback([fo] {
    ibl::io::write_image(*fo, fig3_plot(false));
    std::string base = fo->substr(0, fo->size() - fs::path(*fo).extension().string().size());
    ibl::io::write_image(base + "_2d.png", fig3_plot(true));
    double worst = 0;
    for (double t = 0; t < 1.5; t += 0.001) worst = std::max(worst, nf::shift_invariance_error(t, 0.04));
    iblcli::emit({{"out", *fo}, {"worst_error_s0.04", worst}}, [&] {
      fmt::print("wrote {} and {}_2d.png; at s = 0.04 the 1-D error peaks at {:.2f}% (paper: below 8%)\n", *fo, base,
                 100 * worst);
    });
  });
}

iblcli::Command reg("nearfield", setup);

// Demo: the bike light (9×7) and the flashlight (7×7) simulated, receiver planes at four distances
// and the crypt, each against the exact answer and the far field; Fig. 3.
void nearfield_step(iblcli::DemoContext& ctx) {
  fs::path dir = fs::path(ctx.out_dir) / "nearfield";
  ibl::make_output_folders(fs::path(dir).string());
  json summary;
  nf::Placement origin;
  origin.position = {0, 0, 0};
  for (const char* name : {"bikelight", "flashlight"}) {
    auto lum = nf::make_luminaire(name);
    nf::SimulateDesc sd;
    sd.nx = std::string(name) == "bikelight" ? 9 : 7;
    sd.ny = 7;
    sd.resolution = 96;
    auto t0 = std::chrono::steady_clock::now();
    auto ds = nf::simulate(lum, sd);
    summary[name]["simulate_seconds"] = seconds_since(t0);
    auto ep = nf::incoming_radiance(ds);
    auto lights = nf::place_spotlights(ds, ep, origin, false);
    auto ff =
        nf::far_field_spotlight([&](Vec3 w) { return lum.intensity(w); }, ds.distance, ds.m_max.x, 96, origin, false);
    std::vector<std::pair<std::string, Image>> cells;
    for (double z : {0.15, 0.3, 0.6, 1.2}) {
      nf::PlaneDesc pd;
      pd.z = z;
      pd.resolution = 64;
      // The flashlight's reflector beams stay within ~10° of the axis: look at that window.
      pd.half_extent = std::string(name) == "flashlight" ? 0.012 + 0.2 * z : lum.extent_at(z);
      Image ex = nf::plane_irradiance_exact(lum, pd), ni = nf::plane_irradiance(lights, origin, pd),
            fi = nf::plane_irradiance({ff}, origin, pd);
      auto a = nf::compare(ni, ex), b = nf::compare(fi, ex);
      summary[name]["planes"].push_back({{"z", z}, {"near_field", stats_json(a)}, {"far_field", stats_json(b)}});
      auto tm = same_exposure({ex, ni, fi});
      cells.push_back({fmt::format("exact z={}", z), tm[0]});
      cells.push_back({fmt::format("near {:.0f}%", 100 * a.rel_rms), tm[1]});
      cells.push_back({fmt::format("far {:.0f}%", 100 * b.rel_rms), tm[2]});
    }
    std::string png = (dir / fmt::format("{}_planes.png", name)).string();
    ibl::io::write_image(png, ibl::io::contact_sheet(cells, 3, 128, 128,
                                                     fmt::format("{} {}x{}: exact | near field | far field (RMS error)",
                                                                 name, ds.nx, ds.ny)));
    ctx.pictures.push_back({fmt::format("nearfield {} planes (exact|near|far)", name), png});
    if (std::string(name) == "bikelight") {
      auto scene = ibl::lab::load_scene("crypt");
      nf::SceneView sv(ibl::lab::diffuse_surfaces(scene), scene.name);
      ibl::geometry::Camera view;
      view.eye = {0.9, 1.5, 0.9};
      view.target = {-1.1, 0.3, -1.5};
      view.fov_y_deg = 55;
      view.width = view.height = 160;
      LightOpts lo;
      auto pl = placement_of(lo);
      auto sl = nf::place_spotlights(ds, ep, pl, true);
      t0 = std::chrono::steady_clock::now();
      Image ni = nf::render_spotlights(sv, sl, view, true);
      summary[name]["crypt_160_seconds"] = seconds_since(t0);
      Image ex = nf::render_exact(sv, lum, pl, view, true);
      auto ffc =
          nf::far_field_spotlight([&](Vec3 w) { return lum.intensity(w); }, ds.distance, ds.m_max.x, 96, pl, true);
      Image fi = nf::render_spotlights(sv, {ffc}, view, true);
      auto a = nf::compare(ni, ex), b = nf::compare(fi, ex);
      summary[name]["crypt"] = {{"near_field", stats_json(a)}, {"far_field", stats_json(b)}};
      auto tm = same_exposure({ex, ni, fi});
      const char* tags[] = {"exact", "near", "far"};
      for (int k = 0; k < 3; ++k) {
        std::string p = (dir / fmt::format("crypt_{}.png", tags[k])).string();
        ibl::io::write_image(p, tm[static_cast<size_t>(k)]);
        double e = k == 1 ? a.rel_rms : b.rel_rms;
        ctx.pictures.push_back({k == 0 ? std::string("nearfield crypt, exact bike light")
                                       : fmt::format("crypt {} field, RMS {:.0f}%", tags[k], 100 * e),
                                p});
      }
    }
  }
  std::string f3 = (dir / "fig3.png").string();
  ibl::io::write_image(f3, fig3_plot(false));
  ctx.pictures.push_back({"nearfield E_r(theta0), Fig. 3", f3});
  ctx.summary["nearfield"] = summary;
}

iblcli::DemoStep step("nearfield", 75, nearfield_step);

}  // namespace
