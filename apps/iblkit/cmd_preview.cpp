// iblkit preview PROBE OUT.png: tone-mapped picture of an HDR image.
#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"

namespace {

void setup(CLI::App& app) {
  struct Opts {
    std::string in, out, curve = "aces";
    double exposure = 0;
    bool fixed = false, sanitize = false;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("input", o->in, "HDR image")->required();
  app.add_option("output", o->out, "PNG (or JPEG) to write")->required();
  app.add_option("--exposure", o->exposure, "exposure in stops (added to auto exposure unless --fixed)");
  app.add_flag("--fixed", o->fixed, "no auto exposure: scale by 2^exposure only");
  app.add_option("--curve", o->curve, "tone curve: aces, reinhard, clamp")
      ->check(CLI::IsMember({"aces", "reinhard", "clamp"}))
      ->capture_default_str();
  app.add_flag("--sanitize", o->sanitize, "replace NaN/Inf/negative pixels by 0 instead of failing");
  app.footer("Example:\n  iblkit preview probe.exr probe.png --exposure -1 --curve reinhard");
  app.callback([o] {
    ibl::io::ReadReport rep;
    ibl::Image img = ibl::io::read_image(o->in, {o->sanitize, 0}, &rep);
    ibl::io::ToneMapDesc td;
    td.auto_exposure = !o->fixed;
    td.exposure_stops = o->exposure;
    td.curve = o->curve == "aces"       ? ibl::io::ToneCurve::Aces
               : o->curve == "reinhard" ? ibl::io::ToneCurve::Reinhard
                                        : ibl::io::ToneCurve::Clamp;
    double scale = (td.auto_exposure ? ibl::io::auto_exposure_scale(img) : 1.0) * std::exp2(td.exposure_stops);
    ibl::io::write_image(o->out, ibl::io::tonemap(img, td));
    nlohmann::json j = {{"input", o->in}, {"output", o->out}, {"scale", scale}, {"curve", o->curve}};
    iblcli::emit(j, [&] { fmt::print("wrote {} (exposure scale {:.4g}, {})\n", o->out, scale, o->curve); });
  });
}

iblcli::Command reg("preview", setup);

}  // namespace
