// iblkit fuse eval PROBES --scene SCENE --at x,y,z … : fused maps against the lab's exact local radiance
// map (image RMSE, irradiance error on 20480 normals) for every blend with and without visibility, with
// pictures; --view adds a pinhole view of the back-projected probes (the thesis's Fig. 7.8). Also the
// "fusion" step of `iblkit demo`.
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "fuse_cli.h"
#include "fusion_pictures.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/fusion/evaluate.h"
#include "iblkit/fusion/local_lights.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
#include "iblkit/lab/truth.h"

namespace iblcli {

namespace {

namespace fs = std::filesystem;
using ibl::Image;
using ibl::Vec3;
namespace fu = ibl::fusion;

struct EvalOpts {
  FuseOpts f;
  std::string probes, scene, out, view;
  std::vector<std::string> at;
  int truth_samples = 4, area_samples = 32;
};

// The lab's exact answers as the evaluation's reference: the local radiance map (truth_samples² sub-pixel
// samples, area_samples shadow rays per area light) and the radiance along view rays.
fu::Reference lab_reference(const ibl::lab::Scene& scene, int truth_samples, int area_samples) {
  fu::Reference ref;
  ref.radiance_map = [&scene, truth_samples, area_samples](Vec3 x, int size) {
    ibl::lab::TruthDesc td;
    td.size = size;
    td.samples = truth_samples;
    td.area_samples = area_samples;
    td.bands = 0;
    return ibl::lab::ground_truth(scene, x, td).radiance;
  };
  ref.radiance_along = [&scene, area_samples](Vec3 x, const std::vector<Vec3>& dirs) {
    ibl::lab::RenderDesc rd = scene.render;
    rd.area_samples = area_samples;
    return ibl::lab::radiance_along(scene, x, dirs, rd);
  };
  return ref;
}

std::string point_name(Vec3 x) { return fmt::format("({:g}, {:g}, {:g})", x.x, x.y, x.z); }

// Evaluates every blend × visibility at each point (fusion/evaluate.h); returns the rows and writes
// pictures into dir.
std::vector<fu::EvalRow> evaluate(const fu::ProbeSet& set, const ibl::lab::Scene& scene,
                                  const std::vector<Vec3>& points, const FuseOpts& fo, int truth_samples,
                                  int area_samples, const fs::path& dir,
                                  std::vector<std::pair<std::string, std::string>>* pictures, const std::string& view) {
  ibl::make_output_folders(fs::path(dir).string());
  const fu::Reference ref = lab_reference(scene, truth_samples, area_samples);
  fu::EvalDesc ed;
  ed.fuse = fuse_desc(fo);
  if (!view.empty()) ed.view = parse_vec3(view, "--view");
  std::vector<fu::EvalRow> rows;
  for (size_t k = 0; k < points.size(); ++k) {
    const std::string pname = point_name(points[k]);
    const fu::PointEval pe = fu::evaluate_point(set, points[k], ref, ed);
    double scale = ibl::io::auto_exposure_scale(pe.truth.image);
    std::vector<std::pair<std::string, Image>> sheet = {{"lab truth " + pname, tone(pe.truth.image, scale)}};
    for (size_t i = 0; i < pe.rows.size(); ++i) {
      const auto& r = pe.rows[i];
      sheet.push_back({fmt::format("{}{}: RMSE {:.3f}, E err {:.1f}%", fu::blend_name(r.blend),
                                   r.visibility ? "" : " no visibility", r.image_rmse, 100 * r.irradiance_mean_rel),
                       tone(pe.maps[i].radiance.image, scale)});
      if (r.blend == fu::Blend::Footprint && r.visibility)
        sheet.push_back(
            {"coverage (footprint, visibility)", coverage_picture(pe.maps[i], static_cast<int>(set.probes.size()))});
      rows.push_back(r);
    }
    std::string png = (dir / fmt::format("point{}.png", k)).string();
    ibl::io::write_image(
        png, ibl::io::contact_sheet(sheet, 2, 512, 256, "fused vs lab truth at " + pname + " (same exposure)"));
    if (pictures) pictures->push_back({"fusion vs truth at " + pname, png});
    if (ed.view) {
      // The thesis's Fig. 7.8: the back-projected probes seen from x, angle blend, visibility off/on.
      double s = ibl::io::auto_exposure_scale(pe.view_truth);
      std::vector<std::pair<std::string, Image>> vs = {{"lab truth", tone(pe.view_truth, s)}};
      for (const auto& v : pe.views)
        vs.push_back({fmt::format("{} blend, visibility {}", fu::blend_name(v.blend),
                                  v.visibility ? "on" : "off (thesis Fig. 7.8)"),
                      tone(v.image, s)});
      std::string vpng = (dir / fmt::format("point{}_view.png", k)).string();
      ibl::io::write_image(vpng, ibl::io::contact_sheet(vs, 3, 320, 200, "view from " + pname + " along " + view));
      if (pictures) pictures->push_back({"fusion view from " + pname, vpng});
    }
  }
  return rows;
}

nlohmann::json rows_json(const std::vector<fu::EvalRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : rows)
    a.push_back({{"point", point_name(r.point)},
                 {"blend", fu::blend_name(r.blend)},
                 {"visibility", r.visibility},
                 {"image_rmse", r.image_rmse},
                 {"irradiance_mean_rel", r.irradiance_mean_rel},
                 {"irradiance_max_rel", r.irradiance_max_rel},
                 {"fused", r.coverage.fused},
                 {"unseen", r.coverage.unseen},
                 {"left_proxy", r.coverage.left_proxy}});
  return a;
}

void print_rows(const std::vector<fu::EvalRow>& rows) {
  fmt::print(
      "| point | blend | visibility | image RMSE (rel.) | irradiance error mean / max | fused / unseen / left |\n");
  fmt::print("| --- | --- | --- | --- | --- | --- |\n");
  for (const auto& r : rows)
    fmt::print("| {} | {} | {} | {:.3f} | {:.1f}% / {:.1f}% | {:.1f}% / {:.1f}% / {:.1f}% |\n", point_name(r.point),
               fu::blend_name(r.blend), r.visibility ? "on" : "off", r.image_rmse, 100 * r.irradiance_mean_rel,
               100 * r.irradiance_max_rel, 100 * r.coverage.fused, 100 * r.coverage.unseen,
               100 * r.coverage.left_proxy);
}

void run_eval(const EvalOpts& o) {
  auto set = load_probes_cli(o.probes, o.f.proxy_depth);
  auto scene = ibl::lab::load_scene(o.scene);
  std::vector<Vec3> pts;
  for (const auto& a : o.at) pts.push_back(parse_vec3(a, "--at"));
  if (pts.empty()) ibl::fail(ibl::ErrorKind::Value, "fuse eval: give at least one --at point");
  auto t0 = std::chrono::steady_clock::now();
  auto rows = evaluate(set, scene, pts, o.f, o.truth_samples, o.area_samples, o.out, nullptr, o.view);
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json j = {{"scene", scene.name},    {"probes", o.probes},      {"size", o.f.size},
                      {"samples", o.f.samples}, {"rows", rows_json(rows)}, {"seconds", secs}};
  ibl::write_json_file((fs::path(o.out) / "eval.json").string(), j);
  emit(j, [&] {
    fmt::print("{} fused with {} probes, {}×{} lat-long, {}×{} rays per pixel; truth {}×{} samples ({:.1f} s)\n",
               scene.name, set.probes.size(), 2 * o.f.size, o.f.size, o.f.samples, o.f.samples, o.truth_samples,
               o.truth_samples, secs);
    print_rows(rows);
    fmt::print("wrote {}/eval.json and point*.png\n", o.out);
  });
}

}  // namespace

void setup_eval(CLI::App& fuse) {
  auto* c = fuse.add_subcommand(
      "eval", "Fused maps against the lab's exact local radiance map (every blend, visibility on/off)");
  auto* o = iblcli::app_owned<EvalOpts>();
  o->f.size = 64;
  o->f.samples = 2;
  c->add_option("probes", o->probes, "probe set captured by `iblkit lab capture SCENE --fusion`")->required();
  c->add_option("--scene", o->scene, "the lab scene the probes show (name or file)")->required();
  c->add_option("--at", o->at, "a point x,y,z off the probes (repeat)")->required();
  c->add_option("--truth-samples", o->truth_samples, "n×n sub-pixel samples of the truth")->capture_default_str();
  c->add_option("--area-samples", o->area_samples, "shadow rays per area light of the truth")->capture_default_str();
  c->add_option("--view", o->view, "also a pinhole view (90°) from each point along this direction x,y,z");
  c->add_option("-o,--out", o->out, "folder for eval.json and pictures")->required();
  add_fuse_options(*c, o->f);
  c->footer(
      "Example:\n  iblkit lab capture t-corridor --fusion --probe 0,1.5,-1 --probe 0,1.5,5 --size 128 --out tc\n"
      "  iblkit fuse eval tc/probes.json --scene t-corridor --at -2,1.5,-1 --view 1,0,0 --out eval");
  c->callback([o] { run_eval(*o); });
}

namespace {

// Demo: the thesis's T corridor with two probes (one at the junction, one down the stem), fused in the
// crossbar with and without visibility against the lab's truth (Fig. 7.8), and the localised lights
// at a point in the stem; a few seconds.
void demo_step(DemoContext& ctx) {
  fs::path dir = fs::path(ctx.out_dir) / "fusion";
  ibl::make_output_folders(fs::path(dir).string());
  auto scene = ibl::lab::load_scene("t-corridor");
  ibl::lab::SequenceDesc sd;
  sd.capture.size = 128;
  sd.capture.samples = 2;  // anti-aliased probes: a point-sampled light's edge aliases in every fused map
  sd.capture.render = scene.render;
  sd.out_dir = (dir / "probes").string();
  sd.sheet_probes = 0;
  auto t0 = std::chrono::steady_clock::now();
  auto r = ibl::lab::write_probe_set(scene, {{0, 1.5, -1}, {0, 1.5, 5}}, sd);
  double capture_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fu::LoadDesc ld;
  ld.use_depth_files = false;  // depth from the proxy, as with real probes
  ld.write_cache = false;
  auto set = fu::load_probe_set(r.manifest, ld);
  FuseOpts fo;
  fo.size = 32;
  fo.samples = 2;
  // The thesis's Fig. 7.8: from the crossbar looking down the bright arm, which the stem probe cannot see.
  auto rows = evaluate(set, scene, {{-2, 1.5, -1}}, fo, 2, 8, dir, &ctx.pictures, "1,0,0");
  // The localised lights at the point, on the fused map.
  FuseOpts lo;
  lo.size = 64;
  fu::LocalMap ll = fu::fuse(set, {0, 1.5, 1.0}, fuse_desc(lo));
  auto ls = fu::localize_lights(ll, {16});
  std::string png = (dir / "fused_lights.png").string();
  ibl::io::write_image(png,
                       fused_sheet(ll, 2, &ls, "t-corridor fused at (0, 1.5, 1): map, coverage, 16 localised lights"));
  ctx.pictures.push_back({"fusion: map, coverage, lights", png});
  nlohmann::json s = {{"capture_seconds", capture_s}, {"rows", rows_json(rows)}, {"coverage_fused", ll.stats.fused}};
  ctx.summary["fusion"] = s;
}

DemoStep demo("fusion", 70, demo_step);

}  // namespace
}  // namespace iblcli
#endif  // IBLKIT_HAVE_GEOMETRY
