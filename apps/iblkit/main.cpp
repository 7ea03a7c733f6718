// iblkit: image-based lighting with captured light. One subcommand per file (cmd_*.cpp), each
// registering its setup with iblcli::Command; the table below lists them all.
//
// Start-up (docs/startup.md): this executable holds the light modules; the subcommands that need
// Embree, assimp or OpenGL live in plugins beside it (libiblkit_<name>.so), loaded only when one of
// them runs, so that `iblkit --help`, `iblkit sh` and the other light commands start in a few
// milliseconds. The table is what --help prints without loading anything.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string_view>

#include <fmt/format.h>
#include <oneapi/tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/plugin.h"

namespace {

struct Subcommand {
  const char* name;
  const char* description;
  const char* plugin;  // the plugin that holds its code, or nullptr: this executable
};

// Every subcommand, in the order --help lists them.
constexpr Subcommand kSubcommands[] = {
    {"info", "Describe a probe: size, mapping, range, total power", nullptr},
    {"convert", "Convert a probe to another mapping, size or file format", nullptr},
    {"preview", "Write a tone-mapped PNG of an HDR image", nullptr},
    {"lights", "Directional lights from a probe: median cut, variance cut, irradiance optimisation", nullptr},
    {"sh", "Project a probe onto spherical harmonics; export, window, render irradiance", nullptr},
    {"eval", "Irradiance error of light sets against the exact ground truth (Madsen & Laursen Fig. 4)", nullptr},
    {"ilf", "Incident light fields: probe sequences -> SH grids, queries, slices", nullptr},
    {"hdr", "HDR images from brackets of photographs: response recovery, alignment, merge (hdr merge)", nullptr},
    {"probe", "Probes from photographs: a chrome ball's one or two views unwarped with the real optics", nullptr},
    {"specular", "Engine maps: GGX-prefiltered specular cube map (KTX2, all mips), irradiance cube, DFG table",
     nullptr},
#ifdef IBLKIT_HAVE_GEOMETRY
    {"lab", "Analytic lighting scenes: synthetic captures and exact ground truth", "geometry"},
    {"fuse", "Local environment maps anywhere from probes on a proxy mesh (Pedersen 2008)", "geometry"},
    {"nearfield", "Near-field luminaires: simulated acquisition, textured spotlights, exact comparison", "geometry"},
    {"render", "Render an object lit by a probe, SH, an SH grid, lights or a luminaire (CPU reference or OpenGL)",
     "geometry"},
    {"composite", "Composite a virtual object into a photograph with its shadows (differential rendering)", "geometry"},
    {"camera", "The camera of a photograph: pose and lens from points or a chessboard (OpenCV), calibration, checks",
     "geometry"},
#endif
#if defined(IBLKIT_HAVE_GL) && defined(IBLKIT_HAVE_GLFW)
    {"view", "Interactive viewer (GLFW window): orbit, move the object, switch lightings", "view"},
#endif
    {"web", "Write the three.js viewer folder with probes, light sets and SH grids to open in a browser", nullptr},
    {"serve", "Serve a web viewer folder (iblkit demo writes one) to a browser on this machine", nullptr},
    {"demo", "Run the built-in demo: a real probe through every module, pictures and numbers", nullptr},
};

// The demo runs the demo steps of every module, so it loads every plugin that has some.
constexpr const char* kDemoPlugins[] = {
#ifdef IBLKIT_HAVE_GEOMETRY
    "geometry",
#endif
    nullptr};

// The subcommand named on the command line: the first argument that is not an option (the global
// options --json, -q/--quiet, --help and --version take no value), or nullptr.
const Subcommand* requested(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-') continue;
    for (const auto& s : kSubcommands)
      if (std::strcmp(s.name, argv[i]) == 0) return &s;
    return nullptr;
  }
  return nullptr;
}

// Loads the code a subcommand needs.
void load_for(const Subcommand& s) {
  if (s.plugin) ibl::plugin::load(s.plugin);
  if (std::string_view(s.name) == "demo")
    for (const char* p : kDemoPlugins)
      if (p) ibl::plugin::load(p);
}

int report(const std::string& what) {
  iblcli::progress_done();
  std::fprintf(stderr, "iblkit: error: %s\n", what.c_str());
  return 1;
}

}  // namespace

// TBB's worker threads, joined when main returns rather than left to end while the process exits (where,
// in a sanitizer build, LeakSanitizer's exit-time scan of the threads races with them).
struct WorkerThreads {
  oneapi::tbb::task_scheduler_handle handle{oneapi::tbb::attach{}};
  ~WorkerThreads() { oneapi::tbb::finalize(handle, std::nothrow); }
};

int main(int argc, char** argv) {
  WorkerThreads workers;
  ibl::remove_temp_files_on_signals();  // Ctrl-C or a kill mid-write leaves no temporary file behind
  CLI::App app{
      "iblkit: image-based lighting from captured light.\n"
      "Turns HDR light probes into spherical harmonics, directional lights and other representations,\n"
      "and measures how wrong each one is.\n\n"
      "Examples:\n"
      "  iblkit info probe.exr\n"
      "  iblkit sh probe.exr --bands 3 --format threejs\n"
      "  iblkit demo --out demo-out --only mappings,sh",
      "iblkit"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "iblkit 0.1.0");
  auto& g = iblcli::globals();
  app.add_flag("--json", g.json, "print results as JSON on stdout");
  app.add_flag("-q,--quiet", g.quiet, "no progress bar or chatter on stderr");
  const Subcommand* chosen = requested(argc, argv);
  try {
    if (chosen) load_for(*chosen);
  } catch (const ibl::Error& e) {
    return report(e.what());
  }
  const auto& reg = iblcli::command_registry();
  for (const auto& c : reg)
    if (std::none_of(std::begin(kSubcommands), std::end(kSubcommands),
                     [&](const Subcommand& s) { return c.name == s.name; })) {
      std::fprintf(stderr, "iblkit: internal error: subcommand '%s' is registered but not listed in main.cpp\n",
                   c.name.c_str());
      return 1;
    }
  for (const auto& s : kSubcommands) {
    CLI::App* sub = app.add_subcommand(s.name, s.description);
    sub->fallthrough();
    auto it = std::find_if(reg.begin(), reg.end(), [&](const auto& c) { return c.name == s.name; });
    if (it != reg.end()) {
      it->setup(*sub);
    } else if (&s == chosen) {
      std::fprintf(stderr, "iblkit: internal error: subcommand '%s' has no code in %s\n", s.name,
                   s.plugin ? ibl::plugin::path_of(s.plugin).c_str() : "this executable");
      return 1;
    }
  }
  // Before a subcommand runs: no output is one of its inputs (cli.h, check_outputs).
  std::function<void(CLI::App*)> guard = [&](CLI::App* a) {
    for (CLI::App* sub : a->get_subcommands({})) {
      if (sub->get_subcommands({}).empty()) sub->parse_complete_callback([sub] { iblcli::check_outputs(*sub); });
      guard(sub);
    }
  };
  guard(&app);
  try {
    ibl::OutputTransaction outputs;  // a command that fails leaves its outputs as they were (atomic_file.h)
    app.parse(argc, argv);
    outputs.commit();
  } catch (const CLI::ParseError& e) {
    const std::string unknown =
        e.get_exit_code() != 0 ? iblcli::unknown_subcommand(app, argc, argv) : "";  // not for --help
    if (!unknown.empty()) return std::fprintf(stderr, "iblkit: error: %s\n", unknown.c_str()), 1;
    return app.exit(e);
  } catch (const ibl::Error& e) {
    return report(iblcli::for_command(app, e.what()));  // the library's parameter hints as this command's flags
  } catch (const std::bad_alloc&) {
    // An allocation the library did not check before it made it: what ran, and what to lower.
    const std::string sizes = iblcli::size_options(app);
    return report(fmt::format("out of memory (this process's memory limit or the machine's): {}",
                              sizes.empty() ? "give the command smaller inputs or sizes" : "lower " + sizes));
  } catch (const std::exception& e) {
    return report(e.what());
  }
  return 0;
}
