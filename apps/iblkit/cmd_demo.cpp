// iblkit demo --out DIR: what `make demo` runs. Starts from a real probe (blender-data's forest.exr
// by default) and runs every registered demo step: mappings, SH, lights, … Each step writes its
// pictures and numbers into DIR; the demo ends with DIR/contact_sheet.png and DIR/summary.json.
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/sphere/envmap.h"

namespace {

namespace fs = std::filesystem;
using ibl::sphere::MappingKind;

// Step 1: the probe in every mapping, with previews and the power kept by each conversion.
void mappings_step(iblcli::DemoContext& ctx) {
  auto env = ibl::io::read_envmap(ctx.probe);
  ibl::make_output_folders(fs::path(fs::path(ctx.out_dir) / "mappings").string());
  struct Target {
    MappingKind kind;
    int w, h;
  };
  const Target targets[] = {{MappingKind::LatLong, 512, 256},    {MappingKind::MirrorBall, 256, 256},
                            {MappingKind::Angular, 256, 256},    {MappingKind::CubeHCross, 512, 384},
                            {MappingKind::CubeVCross, 384, 512}, {MappingKind::CubeStrip, 768, 128},
                            {MappingKind::Octahedral, 256, 256}};
  auto p0 = env.integral();
  double lum0 = ibl::luminance(ibl::Vec3{p0[0], p0[1], p0[2]});
  double scale = ibl::io::auto_exposure_scale(env.image);
  ibl::io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(scale);
  nlohmann::json power = nlohmann::json::object();
  for (const auto& t : targets) {
    ibl::sphere::Mapping m(t.kind, t.w, t.h);
    ibl::sphere::EnvMap out(ibl::sphere::resample(env, m), m);
    std::string name = ibl::sphere::mapping_name(t.kind);
    std::string base = (fs::path(ctx.out_dir) / "mappings" / name).string();
    ibl::io::write_image(base + ".exr", out.image);
    ibl::io::write_image(base + ".png", ibl::io::tonemap(out.image, td));
    auto p = out.integral();
    power[name] = ibl::luminance(ibl::Vec3{p[0], p[1], p[2]}) / lum0;
    ctx.pictures.push_back({name, base + ".png"});
  }
  ctx.summary["probe"] = ctx.probe;
  ctx.summary["mappings_power_ratio"] = power;
}

iblcli::DemoStep mappings("mappings", 10, mappings_step);

void setup(CLI::App& app) {
  struct Opts {
    std::string out = "demo-out", probe;
    std::vector<std::string> only;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("-o,--out", o->out, "folder for the pictures and numbers")->capture_default_str();
  app.add_option("--probe", o->probe, "probe to start from (default: blender-data's forest.exr)");
  app.add_option("--only", o->only, "run only these steps, comma-separated (mappings, sh, lights, lab, ilf, render, …)")
      ->delimiter(',');
  app.footer(
      "Examples:\n  iblkit demo --out demo-out --only sh,lights\n  iblkit demo --out d --probe "
      "../shared/probes/ict/uffizi_latlong_256.hdr --only mappings,sh");
  app.callback([o] {
    iblcli::DemoContext ctx;
    ctx.out_dir = o->out;
    ctx.probe = o->probe.empty() ? iblcli::default_probe() : o->probe;
    ibl::make_output_folders(fs::path(ctx.out_dir).string());
    auto& steps = iblcli::demo_registry();
    std::stable_sort(steps.begin(), steps.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
    for (const auto& name : o->only)
      if (std::none_of(steps.begin(), steps.end(), [&](const auto& s) { return s.name == name; })) {
        std::string known;
        for (const auto& s : steps) known += (known.empty() ? "" : ", ") + s.name;
        ibl::fail(ibl::ErrorKind::Value, "--only: no demo step '{}' (steps: {})", name, known);
      }
    nlohmann::json timings = nlohmann::json::object();
    for (auto& s : steps) {
      if (!o->only.empty() && std::find(o->only.begin(), o->only.end(), s.name) == o->only.end()) continue;
      iblcli::info(fmt::format("demo: {} …", s.name));
      auto t0 = std::chrono::steady_clock::now();
      s.fn(ctx);
      double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      timings[s.name] = secs;
      iblcli::info(fmt::format("demo: {} done in {:.2f} s", s.name, secs));
    }
    ctx.summary["step_seconds"] = timings;
    // Contact sheet of every picture the steps wrote.
    std::vector<std::pair<std::string, ibl::Image>> pics;
    for (auto& [caption, path] : ctx.pictures) pics.push_back({caption, ibl::io::read_image(path)});
    std::string sheet = (fs::path(ctx.out_dir) / "contact_sheet.png").string();
    if (!pics.empty())
      ibl::io::write_image(
          sheet, ibl::io::contact_sheet(pics, 4, 300, 170, "iblkit demo: " + fs::path(ctx.probe).filename().string()));
    ibl::write_json_file((fs::path(ctx.out_dir) / "summary.json").string(), ctx.summary, 2);
    iblcli::emit(ctx.summary, [&] {
      fmt::print("demo wrote {} pictures into {}/\n", ctx.pictures.size(), ctx.out_dir);
      fmt::print("  contact sheet: {}\n  numbers:       {}/summary.json\n", sheet, ctx.out_dir);
      for (auto& [name, secs] : timings.items()) fmt::print("  step {:<12} {:.2f} s\n", name, secs.get<double>());
    });
  });
}

iblcli::Command reg("demo", setup);

}  // namespace
