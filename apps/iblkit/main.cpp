// iblkit: image-based lighting with captured light. One subcommand per file (cmd_*.cpp), each
// registering itself with iblcli::Command.
#include <algorithm>
#include <cstdio>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "iblkit/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{
      "iblkit: image-based lighting from captured light.\n"
      "Turns HDR light probes into spherical harmonics, directional lights and other representations,\n"
      "and measures how wrong each one is.\n\n"
      "Examples:\n"
      "  iblkit info probe.exr\n"
      "  iblkit sh probe.exr --bands 3 --format threejs\n"
      "  iblkit demo --out demo-out",
      "iblkit"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "iblkit 0.1.0");
  auto& g = iblcli::globals();
  app.add_flag("--json", g.json, "print results as JSON on stdout");
  app.add_flag("-q,--quiet", g.quiet, "no progress bar or chatter on stderr");
  auto& reg = iblcli::command_registry();
  std::stable_sort(reg.begin(), reg.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
  for (auto& c : reg) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    sub->fallthrough();
    c.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const std::string unknown = e.get_exit_code() != 0 ? iblcli::unknown_subcommand(app, argc, argv) : "";  // not for --help
    if (!unknown.empty()) return std::fprintf(stderr, "iblkit: error: %s\n", unknown.c_str()), 1;
    return app.exit(e);
  } catch (const ibl::Error& e) {
    iblcli::progress_done();
    std::fprintf(stderr, "iblkit: error: %s\n", iblcli::for_command(app, e.what()).c_str());
    return 1;
  } catch (const std::exception& e) {
    iblcli::progress_done();
    std::fprintf(stderr, "iblkit: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
