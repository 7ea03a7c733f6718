// iblkit fuse PROBES --at x,y,z --out local.exr …   the local environment map at a point (docs/fusion.md)
// iblkit fuse PROBES --path path.json --out DIR …   a map and tracked, filtered lights per path point
// iblkit fuse depth PROBES                           trace and cache the probes' depth maps
// (iblkit fuse eval … lives in cmd_fuse_eval.cpp.)
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "fuse_cli.h"
#include "fusion_pictures.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/fusion/local_lights.h"
#include "iblkit/fusion/path.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/sh/project.h"
#include "lights_pictures.h"

namespace iblcli {

namespace fs = std::filesystem;
using ibl::Vec3;
namespace fu = ibl::fusion;

ibl::fusion::ProbeSet load_probes_cli(const std::string& path, bool proxy_depth) {
  fu::LoadDesc ld;
  ld.use_depth_files = !proxy_depth;
  ld.progress = progress_bar();
  auto set = fu::load_probe_set(path, ld);
  progress_done();
  for (const auto& w : set.warnings) info("warning: " + w);
  return set;
}

void add_fuse_options(CLI::App& c, FuseOpts& o) {
  c.add_option("-m,--mapping", o.mapping,
               "output mapping: latlong, hcross, vcross, cubestrip, angular, mirrorball, octahedral")
      ->capture_default_str();
  c.add_option("-s,--size", o.size, "lat-long height, cube face edge or disc diameter of the output")
      ->capture_default_str();
  c.add_option("--blend", o.blend, "nearest (Eq. 5.3), angle (Eq. 5.5) or footprint (ours)")->capture_default_str();
  c.add_flag("--no-visibility", o.no_visibility, "skip the per-probe depth test (reproduces the thesis's Fig. 7.8)");
  c.add_option("--bias", o.bias, "relative depth tolerance ε of the visibility test")->capture_default_str();
  c.add_option("--tolerance", o.tolerance, "absolute depth tolerance τ (metres) of the visibility test")
      ->capture_default_str();
  c.add_option("--samples", o.samples, "n×n rays per output pixel")->capture_default_str();
  c.add_option("--threshold", o.threshold, "angle blend: leave out probes with ω·ω' below this cosine")
      ->capture_default_str();
  c.add_flag("--proxy-depth", o.proxy_depth, "ignore the manifest's depth maps: trace the proxy");
}

ibl::fusion::FuseDesc fuse_desc(const FuseOpts& o) {
  fu::FuseDesc d;
  d.mapping = ibl::sphere::parse_mapping(o.mapping);
  d.size = o.size;
  d.blend = fu::parse_blend(o.blend);
  d.visibility = !o.no_visibility;
  d.depth_bias = o.bias;
  d.depth_tolerance = o.tolerance;
  d.samples = o.samples;
  d.angle_threshold = o.threshold;
  return d;
}

namespace {

// --at: one map, its depth, coverage, SH, optional lights and a picture.
void run_at(const FuseOpts& o, const std::string& probes, const std::string& at, const std::string& out, int nlights,
            int bands) {
  auto set = load_probes_cli(probes, o.proxy_depth);
  Vec3 x = parse_vec3(at, "--at");
  fu::FuseDesc fd = fuse_desc(o);
  fd.progress = progress_bar();
  auto t0 = std::chrono::steady_clock::now();
  fu::LocalMap map = fu::fuse(set, x, fd);
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress_done();
  for (const auto& w : map.warnings) info("warning: " + w);
  fs::path base = fs::path(out).parent_path() / fs::path(out).stem();
  if (!base.parent_path().empty()) ibl::make_output_folders(fs::path(base.parent_path()).string());
  std::string ext = fs::path(out).extension().string();
  if (ext.empty()) ext = ".exr";
  ibl::io::write_image(base.string() + ext, map.radiance.image);
  ibl::io::write_image(base.string() + "_depth" + ext, map.depth);
  ibl::io::write_image(base.string() + "_coverage" + ext, map.coverage);
  // The picture (and the lights) use a lat-long map: the output itself when it is one.
  fu::LocalMap ll;
  if (fd.mapping == ibl::sphere::MappingKind::LatLong) {
    ll = map;
  } else {
    fu::FuseDesc d2 = fd;
    d2.mapping = ibl::sphere::MappingKind::LatLong;
    d2.size = std::max(64, fd.size);
    d2.progress = {};
    ll = fu::fuse(set, x, d2);
  }
  nlohmann::json j = {{"point", {x.x, x.y, x.z}},
                      {"probes", set.probes.size()},
                      {"blend", o.blend},
                      {"visibility", !o.no_visibility},
                      {"mapping", o.mapping},
                      {"size", {map.radiance.image.width(), map.radiance.image.height()}},
                      {"seconds", secs},
                      {"coverage",
                       {{"fused", map.stats.fused},
                        {"left_proxy", map.stats.left_proxy},
                        {"unseen", map.stats.unseen},
                        {"mean_probes", map.stats.mean_probes}}},
                      {"map", base.string() + ext},
                      {"depth", base.string() + "_depth" + ext}};
  if (bands > 0) {
    auto c = ibl::sh::project(map.radiance, bands);
    ibl::sh::write_coeffs(base.string() + "_sh.json", c);
    j["sh"] = base.string() + "_sh.json";
    j["sh_c00"] = {c.c[0].x, c.c[0].y, c.c[0].z};
  }
  ibl::lights::LightSet ls;
  if (nlights > 0) {
    ls = fu::localize_lights(ll, {nlights});
    if (static_cast<int>(ls.lights.size()) < nlights)
      iblcli::info(
          fmt::format("warning: --lights {}: the {}x{} map gives only {} lights (median cut cannot split further)",
                      nlights, ll.radiance.image.width(), ll.radiance.image.height(), ls.lights.size()));
    ibl::lights::write_lights(base.string() + "_lights.json", ls);
    j["lights"] = base.string() + "_lights.json";
  }
  std::string png = base.string() + ".png";
  ibl::io::write_image(
      png, fused_sheet(ll, static_cast<int>(set.probes.size()), nlights > 0 ? &ls : nullptr,
                       fmt::format("fused at ({}, {}, {}) from {} probes, {} blend{}", x.x, x.y, x.z, set.probes.size(),
                                   o.blend, o.no_visibility ? ", no visibility" : "")));
  j["picture"] = png;
  emit(j, [&] {
    fmt::print("fused {}×{} {} map at ({}, {}, {}) from {} probes in {:.3f} s ({} blend{})\n",
               map.radiance.image.width(), map.radiance.image.height(), o.mapping, x.x, x.y, x.z, set.probes.size(),
               secs, o.blend, o.no_visibility ? ", no visibility" : "");
    fmt::print(
        "  coverage: {:.1f}% fused ({:.2f} probes per point), {:.1f}% left the proxy, {:.1f}% seen by no probe\n",
        100 * map.stats.fused, map.stats.mean_probes, 100 * map.stats.left_proxy, 100 * map.stats.unseen);
    fmt::print("  wrote {}{}, {}_depth{}, {}_coverage{}{}{}, {}\n", base.string(), ext, base.string(), ext,
               base.string(), ext, bands > 0 ? ", " + base.string() + "_sh.json" : "",
               nlights > 0 ? ", " + base.string() + "_lights.json" : "", png);
  });
}

// --path: a map and lights per point; tracked and filtered lights; flicker with and without the filter.
void run_path(const FuseOpts& o, const std::string& probes, const std::string& path_file, const std::string& out,
              int nlights, double tau, bool no_filter) {
  auto set = load_probes_cli(probes, o.proxy_depth);
  auto path = fu::read_path(path_file);
  fu::PathDesc pd;
  pd.fuse = fuse_desc(o);
  if (pd.fuse.mapping != ibl::sphere::MappingKind::LatLong)
    ibl::fail(ibl::ErrorKind::Value, "--path writes lat-long maps (the lights are cut from them); drop --mapping {}",
              o.mapping);
  if (nlights >= 1) pd.lights = nlights;  // else the library's default
  pd.track.filter = !no_filter;
  pd.track.time_constant = tau;
  fs::path dir(out);
  ibl::make_output_folders(fs::path(dir / "frames").string());
  ibl::make_output_folders(fs::path(dir / "lights").string());
  std::vector<std::pair<std::string, ibl::Image>> pics;
  size_t every = std::max<size_t>(1, path.size() / 8);
  auto write_frame = [&](const fu::PathFrame& f) {
    for (const auto& w : f.map.warnings) info(fmt::format("warning: frame {}: {}", f.index, w));
    std::string name = fmt::format("{:04d}", f.index);
    ibl::io::write_image((dir / "frames" / (name + ".exr")).string(), f.map.radiance.image);
    ibl::io::write_image((dir / "frames" / (name + "_depth.exr")).string(), f.map.depth);
    auto lj = ibl::lights::to_json(f.filtered);
    for (size_t i = 0; i < f.filtered.lights.size(); ++i) lj["lights"][i]["id"] = f.filtered_ids[i];
    lj["time"] = f.point.time;
    ibl::write_json_file((dir / "lights" / (name + ".json")).string(), lj);
    if (f.index % every == 0 && pics.size() < 8) {
      ibl::lights::LightSet filt = f.filtered;
      filt.regions = f.cut.regions;  // outlines of this frame's cut; markers at the filtered lights
      pics.push_back({fmt::format("frame {} at ({:.2f}, {:.2f}, {:.2f})", f.index, f.point.position.x,
                                  f.point.position.y, f.point.position.z),
                      light_overlay(f.map.radiance, filt, 512, 8)});
    }
  };
  pd.progress = progress_bar();
  auto r = fu::fuse_path(set, path, pd, write_frame);
  progress_done();
  nlohmann::json j = {
      {"frames", path.size()},
      {"lights", pd.lights},
      {"time_constant", tau},
      {"filter", !no_filter},
      {"seconds", r.seconds},
      {"flicker",
       {{"map", {{"mean", r.map_flicker.mean}, {"max", r.map_flicker.max}}},
        {"lights_unfiltered", {{"mean", r.raw_flicker.mean}, {"max", r.raw_flicker.max}}},
        {"lights_filtered", {{"mean", r.filtered_flicker.mean}, {"max", r.filtered_flicker.max}}}}},
      {"excess_flicker", {{"unfiltered", r.raw_excess}, {"filtered", r.filtered_excess}}},
      {"shadow_light_jitter_deg",
       {{"unfiltered", r.raw_jitter * 180 / ibl::kPi}, {"filtered", r.filtered_jitter * 180 / ibl::kPi}}},
      {"lights_vs_map", {{"unfiltered", r.raw_vs_maps}, {"filtered", r.filtered_vs_maps}}},
      {"out", out}};
  ibl::write_json_file((dir / "path_summary.json").string(), j);
  std::string png = (dir / "path.png").string();
  ibl::io::write_image(png, ibl::io::contact_sheet(pics, 2, 512, 256,
                                                   fmt::format("{} frames, {} tracked lights (filter time constant {})",
                                                               path.size(), pd.lights, tau)));
  emit(j, [&] {
    fmt::print("fused {} frames along {} in {:.2f} s, {} lights each (tracked{})\n", path.size(), path_file, r.seconds,
               pd.lights, no_filter ? "" : fmt::format(", low-pass τ = {}", tau));
    fmt::print("  flicker (frame-to-frame RMS change of the irradiance field / its mean), mean / max over frames:\n");
    fmt::print("    the fused maps themselves   {:7.4f} / {:7.4f}\n", r.map_flicker.mean, r.map_flicker.max);
    fmt::print("    lights, unfiltered          {:7.4f} / {:7.4f}\n", r.raw_flicker.mean, r.raw_flicker.max);
    fmt::print("    lights, filtered            {:7.4f} / {:7.4f}\n", r.filtered_flicker.mean, r.filtered_flicker.max);
    fmt::print("  change the maps do not make (RMS / mean): unfiltered {:.4f}, filtered {:.4f}\n", r.raw_excess,
               r.filtered_excess);
    fmt::print("  shadow lights' jump per frame (first {}, luminance-weighted): unfiltered {:.2f}°, filtered {:.2f}°\n",
               pd.shadow_lights, r.raw_jitter * 180 / ibl::kPi, r.filtered_jitter * 180 / ibl::kPi);
    fmt::print("  lights vs their map's irradiance (RMS / mean): unfiltered {:.4f}, filtered {:.4f}\n", r.raw_vs_maps,
               r.filtered_vs_maps);
    fmt::print("  wrote {}/frames/NNNN.exr (+_depth), {}/lights/NNNN.json, {}/path_summary.json, {}\n", out, out, out,
               png);
  });
}

void run_depth(const std::string& probes, bool force) {
  fu::LoadDesc ld;
  ld.force_depth = force;
  ld.progress = progress_bar();
  auto t0 = std::chrono::steady_clock::now();
  auto set = fu::load_probe_set(probes, ld);
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress_done();
  for (const auto& w : set.warnings) info("warning: " + w);
  nlohmann::json arr = nlohmann::json::array();
  for (const auto& p : set.probes) {
    const char* src = p.depth_source == fu::DepthSource::File    ? "file"
                      : p.depth_source == fu::DepthSource::Cache ? "cache"
                                                                 : "traced";
    arr.push_back(
        {{"image", p.image}, {"depth", p.depth_file}, {"source", src}, {"escape_fraction", p.escape_fraction}});
  }
  nlohmann::json j = {{"probes", arr}, {"seconds", secs}, {"warnings", set.warnings}};
  emit(j, [&] {
    fmt::print("{} probes, proxy {} triangles, {:.2f} s\n", set.probes.size(), set.proxy.triangle_count(), secs);
    for (const auto& a : arr)
      fmt::print("  {:<40} depth {:<7} {}  ({:.1f}% of directions leave the proxy)\n", a["image"].get<std::string>(),
                 a["source"].get<std::string>(), a["depth"].get<std::string>(),
                 100 * a["escape_fraction"].get<double>());
  });
}

void setup(CLI::App& app) {
  struct Opts {
    FuseOpts f;
    std::string probes, at, out, path;
    int lights = 0, bands = 3;
    double tau = fu::PathDesc{}.track.time_constant;
    bool no_filter = !fu::PathDesc{}.track.filter, force = false;
    std::string depth_probes;
  };
  auto* o = iblcli::app_owned<Opts>();
  o->f.size = 128;  // --at and --path write the maps themselves: finer than the library's default
  app.add_option("probes", o->probes, "probe set (iblkit.probes/1)");
  app.add_option("--at", o->at, "the point x,y,z");
  app.add_option("--path", o->path, "a path file (iblkit.path/1 or [[x,y,z], …]): a map and lights per point");
  app.add_option("-o,--out", o->out,
                 "--at: the map (.exr; _depth, _coverage, _sh.json, _lights.json, .png beside it); --path: a folder");
  app.add_option(
      "--lights", o->lights,
      fmt::format("median-cut lights localised by depth (--at: 0 = none; --path: default {})", fu::PathDesc{}.lights));
  app.add_option("--bands", o->bands, "SH bands of the map's projection (0: none)")->capture_default_str();
  app.add_option("--tau", o->tau,
                 "--path: time constant of the lights' low-pass filter (path time units; frames when untimed)")
      ->capture_default_str();
  app.add_flag("--no-filter", o->no_filter, "--path: track identities but do not filter");
  add_fuse_options(app, o->f);
  auto* dep =
      app.add_subcommand("depth", "Trace the probes' missing depth maps on the proxy and cache them beside the probes");
  dep->add_option("probes", o->depth_probes, "probe set (iblkit.probes/1)")->required();
  dep->add_flag("--force", o->force, "trace every depth map again (overwrites the manifest's depth files too)");
  dep->footer("Example:\n  iblkit fuse depth tc/probes.json\n  iblkit fuse depth tc/probes.json --force");
  dep->callback([o] { run_depth(o->depth_probes, o->force); });
  setup_eval(app);
  app.require_subcommand(0, 1);
  app.footer(
      "Examples:\n"
      "  iblkit lab capture t-corridor --fusion --probe 0,1.5,-1 --probe 0,1.5,5 --size 128 --out tc\n"
      "  iblkit fuse tc/probes.json --at 0,1.2,1 --out local.exr --lights 16\n"
      "  iblkit fuse tc/probes.json --at 0,1.2,1 --mapping hcross --size 64 --blend angle --no-visibility --out "
      "fig78.exr\n"
      "  iblkit fuse tc/probes.json --path path.json --out frames\n"
      "  iblkit fuse depth tc/probes.json\n"
      "  iblkit fuse eval tc/probes.json --scene t-corridor --at 0,1.5,0.5 --out eval");
  app.callback([o, &app] {
    for (auto* sub : app.get_subcommands())
      if (sub->parsed()) return;
    if (o->probes.empty()) ibl::fail(ibl::ErrorKind::Value, "fuse: give a probe set (iblkit.probes/1)");
    if (o->at.empty() == o->path.empty()) ibl::fail(ibl::ErrorKind::Value, "fuse: give exactly one of --at and --path");
    if (o->out.empty()) ibl::fail(ibl::ErrorKind::Value, "fuse: --out is required");
    if (!o->at.empty())
      run_at(o->f, o->probes, o->at, o->out, o->lights, o->bands);
    else
      run_path(o->f, o->probes, o->path, o->out, o->lights, o->tau, o->no_filter);
  });
}

Command reg("fuse", setup);

}  // namespace
}  // namespace iblcli
#endif  // IBLKIT_HAVE_GEOMETRY
