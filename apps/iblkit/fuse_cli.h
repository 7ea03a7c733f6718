// Pieces shared by the `iblkit fuse` command files (cmd_fuse.cpp, cmd_fuse_eval.cpp).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/probe_set.h"

namespace iblcli {

// The fusing options every `fuse` form takes.
struct FuseOpts {
  std::string mapping = "latlong", blend = "footprint";
  int size = 128, samples = 1;
  double bias = 0.01, tolerance = 0.10, threshold = 0.0;
  bool no_visibility = false, proxy_depth = false;
};
void add_fuse_options(CLI::App& app, FuseOpts& o);
ibl::fusion::FuseDesc fuse_desc(const FuseOpts& o);
// Loads a probe set with a progress bar; prints its warnings on stderr.
ibl::fusion::ProbeSet load_probes_cli(const std::string& path, bool proxy_depth);
// Adds `fuse eval` (cmd_fuse_eval.cpp).
void setup_eval(CLI::App& fuse);

}  // namespace iblcli
