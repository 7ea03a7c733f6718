// iblkit specular PROBE: the GGX-prefiltered specular cube map with its mip chain (KTX2; EXR faces
// or lat-longs per level), the irradiance cube map, and the split-sum DFG table (engine/).
#include <chrono>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/error.h"
#include "iblkit/engine/dfg.h"
#include "iblkit/engine/diffuse.h"
#include "iblkit/engine/export.h"
#include "iblkit/engine/ggx.h"
#include "iblkit/io/envmap_io.h"

namespace {

using namespace ibl;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void setup(CLI::App& app) {
  struct Opts {
    std::string probe, out, faces, latlong, irradiance, dfg, lod = "linear", frame = "iblkit";
    int size = 256, levels = 0, samples = 1024, irradiance_size = 32, dfg_size = 128;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("probe", o->probe, "HDR probe image (or a folder of six cube faces); not needed for --dfg alone");
  app.add_option("-o,--out", o->out, "write the prefiltered cube map, every level, as KTX2 (RGBA16F)");
  app.add_option("-s,--size", o->size, "face size of level 0 (power of two, 8..4096)")->capture_default_str();
  app.add_option("-l,--levels", o->levels, "mip levels N (0: log2(size) − 3, down to 16², as cmgen)")
      ->capture_default_str();
  app.add_option("--roughness", o->lod,
                 "level → perceptual roughness: linear (m/(N−1), glTF/three.js viewers) or filament (1 − √(1 − "
                 "m/(N−1)), cmgen's levels)")
      ->capture_default_str();
  app.add_option("--frame", o->frame,
                 "world frame of the maps: iblkit (= three.js, glTF) or filament (cmgen's frame of a lat-long)")
      ->capture_default_str();
  app.add_option("--samples", o->samples, "importance samples per texel on the levels too large to convolve exactly")
      ->capture_default_str();
  app.add_option("--faces", o->faces, "also write every level as EXR faces DIR/m<level>_<px|nx|py|ny|pz|nz>.exr");
  app.add_option("--latlong", o->latlong, "also write every level as a lat-long DIR/m<level>.exr");
  app.add_option("--irradiance", o->irradiance,
                 "also write the irradiance cube map E/π (.ktx2, or a folder of six EXR faces)");
  app.add_option("--irradiance-size", o->irradiance_size, "face size of the irradiance cube map")
      ->capture_default_str();
  app.add_option("--dfg", o->dfg, "write the split-sum DFG table (scale, bias) as .png, .exr or .ktx2");
  iblcli::outputs(app, {"--faces", "--irradiance", "--dfg"});  // besides --out (cli.h)
  app.add_option("--dfg-size", o->dfg_size, "size of the DFG table")->capture_default_str();
  auto& rd = iblcli::add_probe_read_options(app);
  app.footer(
      "Examples:\n"
      "  iblkit specular /usr/share/blender/datafiles/studiolights/world/forest.exr --out forest_env.ktx2 --irradiance "
      "forest_irr.ktx2\n"
      "  iblkit specular /usr/share/blender/datafiles/studiolights/world/forest.exr --size 64 --faces forest_faces "
      "--roughness filament --frame filament\n"
      "  iblkit specular --dfg dfg.png");
  app.callback([o, &rd] {
    const bool wants_probe = !o->out.empty() || !o->faces.empty() || !o->latlong.empty() || !o->irradiance.empty();
    if (!wants_probe && o->dfg.empty())
      fail(ErrorKind::Value, "nothing to write: give --out, --faces, --latlong, --irradiance or --dfg");
    if (wants_probe && o->probe.empty())
      fail(ErrorKind::Value, "--out, --faces, --latlong and --irradiance need a PROBE");
    engine::SpecularDesc sd;
    sd.size = o->size;
    sd.levels = o->levels;
    sd.samples = o->samples;
    sd.lod = engine::parse_lod_mapping(o->lod);
    const engine::EngineFrame frame = engine::parse_engine_frame(o->frame);
    engine::specular_level_count(sd);  // checks the options before reading the probe
    if (o->irradiance_size < 1 || o->irradiance_size > 256)
      fail(ErrorKind::Value, "--irradiance-size must be in 1..256 (got {})", o->irradiance_size);
    engine::DfgDesc dd;
    dd.size = o->dfg_size;
    if (dd.size < 4 || dd.size > 1024) fail(ErrorKind::Value, "--dfg-size must be in 4..1024 (got {})", dd.size);

    nlohmann::json j = {{"frame", engine::engine_frame_name(frame)}};
    std::vector<std::string> written;
    if (wants_probe) {
      io::ReadReport rep;
      sphere::EnvMap env = io::read_envmap(o->probe, rd, &rep);
      if (rep.sanitized) iblcli::info(fmt::format("sanitized {} NaN/Inf/negative values", rep.sanitized));
      j["probe"] = o->probe;
      sd.rotation = engine::frame_rotation(frame, env.mapping.kind());
      if (!o->out.empty() || !o->faces.empty() || !o->latlong.empty()) {
        auto t0 = std::chrono::steady_clock::now();
        engine::SpecularCube cube = engine::prefilter_ggx(env, sd, iblcli::progress_bar());
        iblcli::progress_done();
        j["specular_seconds"] = seconds_since(t0);
        j["size"] = sd.size;
        j["roughness_mapping"] = engine::lod_mapping_name(sd.lod);
        nlohmann::json lv = nlohmann::json::array();
        for (size_t m = 0; m < cube.info.size(); ++m) {
          const auto& l = cube.info[m];
          lv.push_back({{"level", m},
                        {"size", cube.cube.size(static_cast<int>(m))},
                        {"roughness", l.roughness},
                        {"alpha", l.alpha},
                        {"method", engine::level_method_name(l.method)},
                        {"source_size", l.source_size},
                        {"seconds", l.seconds}});
        }
        j["levels"] = lv;
        if (!o->out.empty()) engine::write_ktx2(o->out, engine::cube_ktx2(cube.cube)), written.push_back(o->out);
        if (!o->faces.empty()) engine::write_cube_faces(o->faces, cube.cube), written.push_back(o->faces + "/");
        if (!o->latlong.empty())
          engine::write_cube_latlongs(o->latlong, cube.cube), written.push_back(o->latlong + "/");
      }
      if (!o->irradiance.empty()) {
        auto t0 = std::chrono::steady_clock::now();
        engine::write_cube(o->irradiance, engine::irradiance_cube(env, o->irradiance_size, sd.rotation));
        j["irradiance_seconds"] = seconds_since(t0);
        written.push_back(o->irradiance);
      }
    }
    if (!o->dfg.empty()) {
      auto t0 = std::chrono::steady_clock::now();
      engine::write_dfg(o->dfg, engine::dfg_table(dd));
      j["dfg_seconds"] = seconds_since(t0);
      j["dfg_size"] = dd.size;
      written.push_back(o->dfg);
    }
    j["written"] = written;
    iblcli::emit(j, [&] {
      if (j.contains("levels"))
        for (const auto& l : j["levels"])
          fmt::print("level {}  {:4}²  roughness {:.3f}  α {:.4f}  {:10}  {:.2f} s\n", l["level"].get<int>(),
                     l["size"].get<int>(), l["roughness"].get<double>(), l["alpha"].get<double>(),
                     l["method"].get<std::string>(), l["seconds"].get<double>());
      for (const auto& w : written) fmt::print("wrote {}\n", w);
    });
  });
}

iblcli::Command reg("specular", setup);

}  // namespace
