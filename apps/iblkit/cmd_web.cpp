// iblkit web --out DIR: the three.js viewer's folder with the data it opens (web_page.h,
// docs/web.md); `iblkit serve DIR` then opens it in a browser. Also the demo's web step.
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/error.h"
#include "web_page.h"

namespace {

namespace fs = std::filesystem;

void setup(CLI::App& app) {
  struct Opts {
    iblcli::WebPageDesc d;
    std::string screenshot, query = "mode=sh";
    std::string size = "800x600";
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("-o,--out", o->d.out, "folder to write (index.html, viewer.js, three/, data/, iblkit-web.json)")
      ->required();
  app.add_option("-p,--probe", o->d.probes, "HDR probe (any mapping): its SH and a lat-long background; repeatable");
  app.add_option("--specular", o->d.specular,
                 "specular KTX2 (iblkit specular) of the --probe of the same rank; repeatable");
  app.add_option("-l,--lights", o->d.lights, "light set: iblkit.lights/1 JSON or glTF (lights --gltf); repeatable");
  app.add_option("-g,--grid", o->d.grids, "SH grid (.shgrid, or .shtree resampled to dense); repeatable");
  app.add_option("--probe-height", o->d.probe_height, "height of the background lat-long copy")
      ->capture_default_str()
      ->check(CLI::Range(8, 8192));
  app.add_option("--screenshot", o->screenshot, "also take a headless-Chromium screenshot of the page into this PNG");
  iblcli::outputs(app, {"--screenshot"});  // besides --out (cli.h)
  app.add_option("--view", o->query,
                 "viewer URL parameters for the screenshot (docs/web.md), e.g. mode=lights&shadows=4")
      ->capture_default_str();
  app.add_option("--size", o->size, "screenshot size WxH")->capture_default_str();
  app.footer(
      "Example:\n  iblkit web --out view --probe /usr/share/blender/datafiles/studiolights/world/forest.exr\n"
      "  iblkit serve view");
  app.callback([o] {
    if (o->d.probes.empty() && o->d.lights.empty() && o->d.grids.empty())
      ibl::fail(ibl::ErrorKind::Value, "nothing to show: give at least one --probe, --lights or --grid");
    auto m = iblcli::write_web_page(o->d);
    nlohmann::json j = {{"out", o->d.out}, {"manifest", m}};
    if (!o->screenshot.empty()) {
      int w = 0, h = 0;
      if (std::sscanf(o->size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 8192 || h > 8192)
        ibl::fail(ibl::ErrorKind::Value, "--size {}: expected WxH, 16..8192 each", o->size);
      int rc = iblcli::screenshot_page(o->d.out, o->query, o->screenshot, w, h);
      if (rc != 0 || !fs::exists(o->screenshot))
        ibl::fail(ibl::ErrorKind::Io, "Chromium could not take the screenshot (exit {})", rc);
      j["screenshot"] = o->screenshot;
    }
    iblcli::emit(j, [&] {
      fmt::print("wrote the viewer into {}/ ({} probes, {} light sets, {} grids); open it with: iblkit serve {}\n",
                 o->d.out, m["probes"].size(), m["lights"].size(), m["grids"].size(), o->d.out);
      if (!o->screenshot.empty()) fmt::print("screenshot: {}\n", o->screenshot);
    });
  });
}

iblcli::Command reg("web", setup);

// Demo: the page with the demo's probe, its median-cut lights and the ILF step's 16³ grid, and a
// screenshot of each mode where Chromium exists.
void demo_step(iblcli::DemoContext& ctx) {
  if (iblcli::built_page_dir().empty()) {
    iblcli::info("demo: web: the viewer was not built (no npm at build time); skipped");
    ctx.summary["web"] = {{"skipped", "viewer not built"}};
    return;
  }
  fs::path out = fs::path(ctx.out_dir) / "web";
  iblcli::WebPageDesc d;
  d.out = out.string();
  d.probes = {ctx.probe};
  fs::path lights = fs::path(ctx.out_dir) / "lights" / "median-cut_16.json";
  if (fs::exists(lights)) d.lights = {lights.string()};
  fs::path grid = fs::path(ctx.out_dir) / "ilf" / "grid16.shgrid";
  if (fs::exists(grid)) d.grids = {grid.string()};
  auto m = iblcli::write_web_page(d);
  nlohmann::json shots = nlohmann::json::object();
  if (!iblcli::find_chromium().empty()) {
    std::vector<std::pair<std::string, std::string>> views = {{"sh", "mode=sh&eye=0,0.3,1.6"}};
    if (!d.lights.empty()) views.push_back({"lights", "mode=lights&eye=0,1.2,2.4"});
    if (!d.grids.empty()) views.push_back({"grid", "mode=grid"});  // the viewer frames the grid's box
    for (auto& [name, q] : views) {
      std::string png = (out / ("screenshot_" + name + ".png")).string();
      if (iblcli::screenshot_page(out.string(), q, png, 640, 480) == 0 && fs::exists(png)) {
        ctx.pictures.push_back({"web viewer: " + name, png});
        shots[name] = png;
      }
    }
  }
  ctx.summary["web"] = {{"folder", out.string()}, {"screenshots", shots}, {"serve", "iblkit serve " + out.string()}};
}

iblcli::DemoStep step("web", 95, demo_step);

}  // namespace
