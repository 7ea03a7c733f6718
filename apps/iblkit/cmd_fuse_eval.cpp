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
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/fusion/local_lights.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/lab/radiance.h"
#include "iblkit/lab/rng.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
#include "iblkit/lab/truth.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/sphere/pointset.h"

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

// Solid-angle weighted RMS of the luminance difference over the mean luminance of the truth.
double image_rmse(const ibl::sphere::EnvMap& est, const ibl::sphere::EnvMap& truth) {
  const auto& m = truth.mapping;
  double s2 = 0, sy = 0, sw = 0;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      double w = m.solid_angle_estimate(x, y);
      double yt = ibl::luminance(truth.image.rgb(x, y)), ye = ibl::luminance(est.image.rgb(x, y));
      s2 += w * (ye - yt) * (ye - yt);
      sy += w * yt;
      sw += w;
    }
  return sy > 0 ? std::sqrt(s2 / sw) / (sy / sw) : 0;
}

struct Camera {
  Vec3 f, r, u;
  int w = 320, h = 200;
  double tan_half = 1.0;  // 90° horizontal field of view
  Camera(Vec3 forward) {
    f = ibl::normalize(forward);
    Vec3 up = std::abs(f.y) > 0.99 ? Vec3{0, 0, 1} : Vec3{0, 1, 0};
    r = ibl::normalize(ibl::cross(f, up));
    u = ibl::cross(r, f);
  }
  std::vector<Vec3> rays() const {
    std::vector<Vec3> d;
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) {
        double sx = (2 * (i + 0.5) / w - 1) * tan_half, sy = (1 - 2 * (j + 0.5) / h) * tan_half * h / w;
        d.push_back(ibl::normalize(f + r * sx + u * sy));
      }
    return d;
  }
  Image to_image(const std::vector<Vec3>& L) const {
    Image img(w, h, 3);
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) img.set_rgb(i, j, L[static_cast<size_t>(j) * w + i]);
    return img;
  }
};

// The lab's radiance along each ray (4 random streams per ray, averaged).
std::vector<Vec3> truth_rays(const ibl::lab::Scene& scene, Vec3 x, const std::vector<Vec3>& dirs, int area_samples) {
  ibl::lab::RenderDesc rd = scene.render;
  rd.area_samples = area_samples;
  std::vector<Vec3> out(dirs.size());
  ibl::parallel_for(0, static_cast<int64_t>(dirs.size()), [&](int64_t i) {
    Vec3 s;
    for (int k = 0; k < 4; ++k) {
      ibl::lab::Rng rng(ibl::lab::stream_key(rd.seed, 7, static_cast<uint64_t>(i), k));
      s += ibl::lab::radiance(scene, x, dirs[i], rng, rd);
    }
    out[i] = s / 4;
  }, 64);
  return out;
}

struct EvalRow {
  std::string point, blend;
  bool visibility;
  double rmse, irr_mean, irr_max, fused, unseen, left;
};

// Evaluates every blend × visibility at each point; returns the rows and writes pictures into dir.
std::vector<EvalRow> evaluate(const fu::ProbeSet& set, const ibl::lab::Scene& scene, const std::vector<Vec3>& points,
                              const FuseOpts& fo, int truth_samples, int area_samples, const fs::path& dir,
                              std::vector<std::pair<std::string, std::string>>* pictures, const std::string& view) {
  fs::create_directories(dir);
  static const std::vector<Vec3> normals = ibl::sphere::icosphere_face_centres(5);  // 20480 (Madsen & Laursen)
  std::vector<EvalRow> rows;
  for (size_t k = 0; k < points.size(); ++k) {
    Vec3 x = points[k];
    std::string pname = fmt::format("({:g}, {:g}, {:g})", x.x, x.y, x.z);
    ibl::lab::TruthDesc td;
    td.size = fo.size;
    td.samples = truth_samples;
    td.area_samples = area_samples;
    td.bands = 0;
    auto truth = ibl::lab::ground_truth(scene, x, td);
    auto e_truth = ibl::lights::irradiance_ground_truth(truth.radiance, normals);
    double scale = ibl::io::auto_exposure_scale(truth.radiance.image);
    std::vector<std::pair<std::string, Image>> sheet = {{"lab truth " + pname, tone(truth.radiance.image, scale)}};
    for (fu::Blend b : {fu::Blend::Nearest, fu::Blend::Angle, fu::Blend::Footprint})
      for (bool vis : {false, true}) {
        FuseOpts o = fo;
        o.mapping = "latlong";
        o.blend = fu::blend_name(b);
        o.no_visibility = !vis;
        fu::LocalMap m = fu::fuse(set, x, fuse_desc(o));
        auto e = ibl::lights::irradiance_ground_truth(m.radiance, normals);
        auto st = ibl::lights::compare_irradiance(e, e_truth);
        rows.push_back({pname, o.blend, vis, image_rmse(m.radiance, truth.radiance), st.mean_rel, st.max_rel, m.stats.fused,
                        m.stats.unseen, m.stats.left_proxy});
        sheet.push_back({fmt::format("{}{}: RMSE {:.3f}, E err {:.1f}%", o.blend, vis ? "" : " no visibility", rows.back().rmse,
                                     100 * st.mean_rel),
                         tone(m.radiance.image, scale)});
        if (b == fu::Blend::Footprint && vis) sheet.push_back({"coverage (footprint, visibility)", coverage_picture(m, static_cast<int>(set.probes.size()))});
      }
    std::string png = (dir / fmt::format("point{}.png", k)).string();
    ibl::io::write_image(png, ibl::io::contact_sheet(sheet, 2, 512, 256, "fused vs lab truth at " + pname + " (same exposure)"));
    if (pictures) pictures->push_back({"fusion vs truth at " + pname, png});
    if (!view.empty()) {
      // The thesis's Fig. 7.8: the back-projected probes seen from x, angle blend, visibility off/on.
      Camera cam(parse_vec3(view, "--view"));
      auto dirs = cam.rays();
      auto t = truth_rays(scene, x, dirs, area_samples);
      double s = ibl::io::auto_exposure_scale(cam.to_image(t));
      std::vector<std::pair<std::string, Image>> vs = {{"lab truth", tone(cam.to_image(t), s)}};
      for (bool vis : {false, true})
        for (const char* bl : {"angle", "footprint"}) {
          FuseOpts o = fo;
          o.blend = bl;
          o.no_visibility = !vis;
          auto L = fu::fuse_rays(set, x, dirs, fuse_desc(o));
          vs.push_back({fmt::format("{} blend, visibility {}", bl, vis ? "on" : "off (thesis Fig. 7.8)"), tone(cam.to_image(L), s)});
        }
      std::string vpng = (dir / fmt::format("point{}_view.png", k)).string();
      ibl::io::write_image(vpng, ibl::io::contact_sheet(vs, 3, 320, 200, "view from " + pname + " along " + view));
      if (pictures) pictures->push_back({"fusion view from " + pname, vpng});
    }
  }
  return rows;
}

nlohmann::json rows_json(const std::vector<EvalRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : rows)
    a.push_back({{"point", r.point}, {"blend", r.blend}, {"visibility", r.visibility}, {"image_rmse", r.rmse},
                 {"irradiance_mean_rel", r.irr_mean}, {"irradiance_max_rel", r.irr_max}, {"fused", r.fused},
                 {"unseen", r.unseen}, {"left_proxy", r.left}});
  return a;
}

void print_rows(const std::vector<EvalRow>& rows) {
  fmt::print("| point | blend | visibility | image RMSE (rel.) | irradiance error mean / max | fused / unseen / left |\n");
  fmt::print("| --- | --- | --- | --- | --- | --- |\n");
  for (const auto& r : rows)
    fmt::print("| {} | {} | {} | {:.3f} | {:.1f}% / {:.1f}% | {:.1f}% / {:.1f}% / {:.1f}% |\n", r.point, r.blend,
               r.visibility ? "on" : "off", r.rmse, 100 * r.irr_mean, 100 * r.irr_max, 100 * r.fused, 100 * r.unseen,
               100 * r.left);
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
  nlohmann::json j = {{"scene", scene.name}, {"probes", o.probes}, {"size", o.f.size}, {"samples", o.f.samples},
                      {"rows", rows_json(rows)}, {"seconds", secs}};
  ibl::write_json_file((fs::path(o.out) / "eval.json").string(), j);
  emit(j, [&] {
    fmt::print("{} fused with {} probes, {}×{} lat-long, {}×{} rays per pixel; truth {}×{} samples ({:.1f} s)\n", scene.name,
               set.probes.size(), 2 * o.f.size, o.f.size, o.f.samples, o.f.samples, o.truth_samples, o.truth_samples, secs);
    print_rows(rows);
    fmt::print("wrote {}/eval.json and point*.png\n", o.out);
  });
}

}  // namespace

void setup_eval(CLI::App& fuse) {
  auto* c = fuse.add_subcommand("eval", "Fused maps against the lab's exact local radiance map (every blend, visibility on/off)");
  auto* o = new EvalOpts();
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
  c->footer("Example:\n  iblkit lab capture t-corridor --fusion --probe 0,1.5,-1 --probe 0,1.5,5 --size 128 --out tc\n"
            "  iblkit fuse eval tc/probes.json --scene t-corridor --at -2,1.5,-1 --view 1,0,0 --out eval");
  c->callback([o] { run_eval(*o); });
}

namespace {

// Demo: the thesis's T corridor with two probes (one at the junction, one down the stem), fused in the
// crossbar with and without visibility against the lab's truth (Fig. 7.8), and the localised lights
// at a point in the stem; a few seconds.
void demo_step(DemoContext& ctx) {
  fs::path dir = fs::path(ctx.out_dir) / "fusion";
  fs::create_directories(dir);
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
  ibl::io::write_image(png, fused_sheet(ll, 2, &ls, "t-corridor fused at (0, 1.5, 1): map, coverage, 16 localised lights"));
  ctx.pictures.push_back({"fusion: map, coverage, lights", png});
  nlohmann::json s = {{"capture_seconds", capture_s}, {"rows", rows_json(rows)}, {"coverage_fused", ll.stats.fused}};
  ctx.summary["fusion"] = s;
}

DemoStep demo("fusion", 70, demo_step);

}  // namespace
}  // namespace iblcli
#endif  // IBLKIT_HAVE_GEOMETRY
