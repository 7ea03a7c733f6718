// iblkit hdr merge IMG... --out probe.exr: an HDR image from a bracket of photographs (issue 29 §1,
// docs/capture.md).
#include <fmt/format.h>

#include "cli.h"
#include "iblkit/capture/bracket.h"
#include "iblkit/capture/merge.h"
#include "iblkit/capture/response.h"
#include "iblkit/capture/sensor.h"
#include "iblkit/core/error.h"
#include "iblkit/io/dng.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/photo.h"

namespace {

struct MergeOpts {
  std::vector<std::string> inputs;
  std::string out, exposures, response, method = "debevec", response_out, grey_card;
  double scale = 1, reflectance = 0.18, smoothness = ibl::capture::RecoverDesc{}.smoothness;
  bool no_align = false, full_float = false;
};

struct BracketOpts {
  std::string in, out, exposures = "1/256,1/64,1/16,1/4,1", response = "srgb", format = "jpg";
  double full_well = 0, read_noise = 0, f_number = 1, iso = 100;
  int quality = 95, bits = 8;
  uint64_t seed = 0;
  bool linear_raw = false;
};

// iblkit hdr bracket: photographs of an HDR image through the sensor model (capture/sensor.h).
void setup_bracket(CLI::App& app) {
  auto* b = app.add_subcommand("bracket", "Photograph an HDR image as a bracket through the sensor model (for tests)");
  auto* o = iblcli::app_owned<BracketOpts>();
  b->add_option("image", o->in, "linear HDR image (radiance)")->required();
  b->add_option("-o,--out", o->out, "output prefix: PREFIX-0.jpg, PREFIX-1.jpg, …")->required();
  b->add_option("--exposures", o->exposures, "exposure times in seconds")->capture_default_str();
  b->add_option("--f-number", o->f_number, "f-number written to Exif and applied")->capture_default_str();
  b->add_option("--iso", o->iso, "ISO written to Exif and applied")->capture_default_str();
  b->add_option("--response", o->response, "srgb, linear, camera or an iblkit.response/1 file")->capture_default_str();
  b->add_option("--full-well", o->full_well, "photo-electrons at saturation at ISO 100 (0: no shot noise)");
  b->add_option("--read-noise", o->read_noise, "read noise sigma in units of saturation");
  b->add_option("--format", o->format,
                "jpg, png, tif, or dng (a 14-bit raw mosaic: no response, white balance as shot)")
      ->check(CLI::IsMember({"jpg", "png", "tif", "dng"}))
      ->capture_default_str();
  b->add_flag("--linear-raw", o->linear_raw, "with --format dng: every channel at every pixel (LinearRaw), no mosaic");
  b->add_option("--bits", o->bits, "8 or 16")->check(CLI::IsMember({8, 16}))->capture_default_str();
  b->add_option("--quality", o->quality, "JPEG quality")->capture_default_str();
  b->add_option("--seed", o->seed, "noise seed (frame j uses seed + j)")->capture_default_str();
  b->footer(
      "Examples:\n  iblkit hdr bracket probe.exr --out ball\n"
      "  iblkit hdr bracket probe.exr --format tif --bits 16 --response linear --exposures 1/250,1/60,1/15 --out t\n"
      "  iblkit hdr bracket probe.exr --format dng --full-well 30000 --read-noise 3e-4 --out raw");
  b->callback([o] {
    const ibl::Image L = ibl::io::read_image(o->in, {false, 3});
    const auto ex = ibl::capture::parse_exposures(o->exposures);
    if (ex.ev) throw ibl::Error(ibl::ErrorKind::Value, "hdr bracket --exposures takes seconds, not EV steps");
    ibl::capture::SensorDesc s;
    s.response = ibl::capture::response_by_name(o->response);
    s.full_well = o->full_well;
    s.read_noise = o->read_noise;
    s.f_number = o->f_number;
    s.iso = o->iso;
    s.bits = o->bits;
    nlohmann::json files = nlohmann::json::array();
    for (size_t j = 0; j < ex.exposures.size(); ++j) {
      s.exposure_s = ex.exposures[j];
      s.seed = o->seed + j;
      const std::string path = fmt::format("{}-{}.{}", o->out, j, o->format);
      const ibl::io::PhotoMeta meta{s.exposure_s, s.f_number, s.iso, "iblkit", "sensor"};
      if (o->format == "dng")
        ibl::io::write_dng(path, ibl::capture::expose_dng(L, s, {.mosaic = !o->linear_raw}, meta));
      else
        ibl::io::write_photo(path, ibl::capture::expose(L, s), o->bits, meta, o->quality);
      files.push_back(path);
    }
    iblcli::emit({{"files", files}}, [&] {
      for (const auto& f : files) fmt::print("wrote {}\n", f.get<std::string>());
    });
  });
}

void setup(CLI::App& app) {
  app.require_subcommand(1);
  setup_bracket(app);
  auto* m = app.add_subcommand("merge", "Merge a bracket of photographs (JPEG/PNG/TIFF or raw) into an HDR image");
  auto* o = iblcli::app_owned<MergeOpts>();
  m->add_option("images", o->inputs,
                "the bracket: 8-bit JPEG/PNG, 16-bit TIFF/PNG, or raw files (DNG, CR2, NEF, …: linear, no curve)")
      ->required();
  m->add_option("-o,--out", o->out, "HDR image to write (.exr: half floats unless --float)")->required();
  m->add_option("--exposures", o->exposures,
                "exposure of each photograph, in order: seconds (1/250,1/60,1/15) or EV steps (ev:-2,0,2); "
                "default: from Exif");
  m->add_option(
      "--response", o->response,
      "known response curve: srgb, linear, camera or an iblkit.response/1 file; default: recovered (linear for raw "
      "files)");
  m->add_option("--method", o->method, "response recovery: debevec (Debevec & Malik 1997) or robertson (2003)")
      ->check(CLI::IsMember({"debevec", "robertson"}))
      ->capture_default_str();
  m->add_option("--response-out", o->response_out, "write the curve used (iblkit.response/1)");
  m->add_option("--smoothness", o->smoothness,
                "Debevec's smoothness weight kappa (lambda^2 = kappa x data rows per bin; docs/capture.md)")
      ->check(CLI::Range(1e-4, 1e4))
      ->capture_default_str();
  m->add_flag("--no-align", o->no_align, "no translation alignment (Ward's median threshold bitmaps)");
  m->add_option("--scale", o->scale, "multiply the result (after --grey-card)")->capture_default_str();
  m->add_option("--grey-card", o->grey_card,
                "x,y,w,h: pixel rectangle of a grey card: scaled and white-balanced to read --reflectance");
  m->add_option("--reflectance", o->reflectance, "the grey card's reflectance")->capture_default_str();
  m->add_flag("--float", o->full_float, "32-bit float EXR instead of half");
  iblcli::outputs(*m, {"--response-out"});
  m->footer(
      "Example:\n  iblkit hdr merge ball-*.jpg --out ball.exr --response-out ball-curve.json\n"
      "  iblkit hdr merge t-0.tif t-1.tif t-2.tif --exposures 1/250,1/60,1/15 --response linear --out probe_t.exr\n"
      "  iblkit hdr merge raw-0.dng raw-1.dng raw-2.dng raw-3.dng raw-4.dng --out probe_raw.exr");
  m->callback([o] {
    ibl::capture::BracketDesc bd;
    if (!o->exposures.empty()) bd = ibl::capture::parse_exposures(o->exposures);
    ibl::capture::MergeDesc md;
    if (!o->response.empty()) md.response = ibl::capture::response_by_name(o->response);
    md.method = o->method;
    md.recover.smoothness = o->smoothness;
    md.align = !o->no_align;
    md.scale = o->scale;
    md.reflectance = o->reflectance;
    if (!o->grey_card.empty()) {
      const auto v = iblcli::parse_int_list(o->grey_card, "--grey-card");
      if (v.size() != 4) throw ibl::Error(ibl::ErrorKind::Value, "--grey-card takes x,y,w,h (four integers)");
      md.grey_card = std::array<int, 4>{v[0], v[1], v[2], v[3]};
    }
    const auto bracket = ibl::capture::read_bracket(o->inputs, bd);
    if (md.response && !bracket.linear) ibl::capture::check_fits(*md.response, bracket.bits, o->inputs[0], o->response);
    if (bracket.linear) {
      // Raw files are linear in the light: no curve to recover or apply.
      if (!o->response.empty() && o->response != "linear")
        throw ibl::Error(ibl::ErrorKind::Value,
                         fmt::format("{}: a raw file is linear (LibRaw decodes it): drop --response {} (it applies to "
                                     "JPEG/PNG/TIFF brackets)",
                                     o->inputs[0], o->response));
      md.response = ibl::capture::linear_response();
    }
    ibl::capture::MergeReport rep;
    const ibl::Image hdr = ibl::capture::merge_hdr(bracket.frames, md, &rep);
    ibl::io::write_image(o->out, hdr, {.half = !o->full_float});
    if (!o->response_out.empty()) ibl::capture::write_response(o->response_out, rep.response);
    nlohmann::json j = ibl::capture::report_json(rep, bracket.frames);
    j["output"] = o->out;
    j["bits"] = bracket.bits;
    j["exposure_source"] = bracket.exposure_source;
    j["iso_assumed"] = bracket.iso_assumed;
    if (!o->response_out.empty()) j["response_out"] = o->response_out;
    if (bracket.linear)
      j["raw"] = {{"black", bracket.raw.black},
                  {"white", bracket.raw.white},
                  {"pattern", bracket.raw.pattern},
                  {"multipliers", bracket.raw.multipliers}};
    iblcli::emit(j, [&] {
      fmt::print("wrote {} ({}x{}, {} frames, {}-bit, response {})\n", o->out, hdr.width(), hdr.height(),
                 bracket.frames.size(), bracket.bits, rep.response.kind);
      for (size_t f = 0; f < bracket.frames.size(); ++f)
        fmt::print("  {}  exposure {:.6g}  shift {},{}{}\n", bracket.frames[f].name, bracket.frames[f].exposure,
                   rep.shifts[f][0], rep.shifts[f][1], static_cast<int>(f) == rep.reference ? "  (reference)" : "");
      fmt::print("dynamic range  {:.2f} stops (luminance {:.4g} .. {:.4g})\n", rep.dynamic_range_stops,
                 rep.min_luminance, rep.max_luminance);
      fmt::print("pixels         {} well exposed, {} saturated everywhere, {} black everywhere (of {})\n",
                 rep.well_exposed, rep.saturated_everywhere, rep.black_everywhere, rep.pixels);
      fmt::print("noise          {:.3g} (median relative deviation between frames)\n", rep.noise);
      if (bracket.linear)
        fmt::print("raw            {} black {:g} white {:g}, as-shot multipliers {:.4g},{:.4g},{:.4g} (LibRaw)\n",
                   bracket.raw.pattern, bracket.raw.black, bracket.raw.white, bracket.raw.multipliers[0],
                   bracket.raw.multipliers[1], bracket.raw.multipliers[2]);
      if (bracket.iso_assumed) fmt::print("note           no ISO in Exif: ISO 100 assumed\n");
    });
  });
}

iblcli::Command reg("hdr", setup);

}  // namespace
