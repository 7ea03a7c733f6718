// Demo step "capture_chain" (docs/capture.md, "From the set to the composite"): the documented chain run as a user
// runs it — `iblkit lab shoot low-scene2 … --backplate` writes a capture folder (the ball's JPEG brackets from two
// sides, a JPEG backplate with a board on the floor, the truth with the object), `iblkit composite --capture` goes
// from it to the composite JPEG — beside the truth, with the camera's and the composite's errors in summary.json
// under "capture_chain". The two commands run as child processes of this executable, exactly as written in the docs.
#ifdef IBLKIT_HAVE_GEOMETRY
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/capture/backplate.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"

namespace {

namespace fs = std::filesystem;
using ibl::Image;

// Runs `iblkit ARGS` (this executable) quietly; its standard output into `out` when given.
void run_self(const std::string& args, const fs::path& out = {}) {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) ibl::fail(ibl::ErrorKind::Io, "demo: cannot find its own executable ({})", ec.message());
  const std::string cmd =
      fmt::format("'{}' --quiet {}{}", self.string(), args, out.empty() ? " > /dev/null" : " > '" + out.string() + "'");
  const int rc = std::system(cmd.c_str());
  if (rc != 0) ibl::fail(ibl::ErrorKind::Internal, "demo: `iblkit {}` failed (exit {})", args, rc);
}

void chain_step(iblcli::DemoContext& ctx) {
  const fs::path dir = fs::path(ctx.out_dir) / "capture_chain";
  ibl::make_output_folders(dir.string());
  const fs::path set = dir / "set";
  const std::string shoot = fmt::format(
      "lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 384 --height 384 --samples 4 "
      "--bracket 12 --until-unsaturated --ev-step 3 --bounces 1 --noise --wb 1.1,1,0.8 --backplate --out '{}'",
      set.string());
  const std::string composite =
      fmt::format("--json composite --capture '{0}' --out '{1}' --layers '{2}' --register check", set.string(),
                  (dir / "composite.jpg").string(), (dir / "layers").string());
  auto t0 = std::chrono::steady_clock::now();
  run_self(shoot);
  const double shoot_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t0 = std::chrono::steady_clock::now();
  run_self(composite, dir / "composite.json");
  const double chain_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const nlohmann::json j = ibl::read_json_file((dir / "composite.json").string());
  // backplate | composite | truth | 4 × |composite − truth|, linear through the backplate's curve, tone-mapped alike.
  const ibl::capture::Backplate plate = ibl::capture::read_backplate((set / "backplate.jpg").string());
  const Image comp = ibl::capture::read_backplate((dir / "composite.jpg").string()).linear;
  const Image truth = ibl::capture::read_backplate((set / "truth.jpg").string()).linear;
  Image diff(comp.width(), comp.height(), 3);
  for (size_t i = 0; i < diff.size(); ++i) diff.data()[i] = 4 * std::abs(comp.data()[i] - truth.data()[i]);
  ibl::io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(ibl::io::auto_exposure_scale(plate.linear));
  const std::vector<std::pair<std::string, Image>> panels = {{"backplate (JPEG)", ibl::io::tonemap(plate.linear, td)},
                                                             {"composite --capture", ibl::io::tonemap(comp, td)},
                                                             {"truth (the lab)", ibl::io::tonemap(truth, td)},
                                                             {"4 x |composite - truth|", ibl::io::tonemap(diff, td)}};
  const std::string png = (dir / "capture_chain.png").string();
  ibl::io::write_image(png, ibl::io::contact_sheet(panels, 4, 320, 240));
  ctx.pictures.push_back({"capture chain: lab shoot --backplate -> composite --capture, beside the truth", png});
  const auto& e = j.at("errors");
  const auto& c = j.at("camera");
  ctx.summary["capture_chain"] = {{"scene", "low-scene2"},
                                  {"commands", {"iblkit " + shoot, "iblkit " + composite}},
                                  {"camera", c},
                                  {"errors", e},
                                  {"registration", j.value("registration", nlohmann::json::object())},
                                  {"response", j.at("response")},
                                  {"seconds", {{"shoot", shoot_s}, {"composite_capture", chain_s}}}};
  const double yaw = j.contains("registration") ? j.at("registration").value("yaw_deg", 0.0) : 0.0;
  iblcli::info(
      fmt::format("capture chain: camera {:.2f} mm, {:.3f}°, {:.3f} px; the probe's facing agrees with the backplate "
                  "within {:.1f}°; object {:.1f} %, shadow {:.1f} % of its signal (shoot {:.1f} s, chain {:.1f} s)",
                  c.at("eye_error_mm").get<double>(), c.at("view_error_deg").get<double>(),
                  c.at("reprojection_rms_px").get<double>(), std::abs(yaw), 100 * e.at("object").get<double>(),
                  100 * e.at("shadow").get<double>(), shoot_s, chain_s));
}

iblcli::DemoStep step("capture_chain", 95, chain_step);

}  // namespace
#endif  // IBLKIT_HAVE_GEOMETRY
