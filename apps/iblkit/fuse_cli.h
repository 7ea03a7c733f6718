// Pieces shared by the `iblkit fuse` command files (cmd_fuse.cpp, cmd_fuse_eval.cpp).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/sphere/mapping.h"

namespace iblcli {

// The fusing options every `fuse` form takes, initialised from the library's FuseDesc defaults (a
// command that wants another default sets it before add_fuse_options, which shows it in --help).
struct FuseOpts {
  static inline const ibl::fusion::FuseDesc kDefaults{};
  std::string mapping = ibl::sphere::mapping_name(kDefaults.mapping), blend = ibl::fusion::blend_name(kDefaults.blend);
  int size = kDefaults.size, samples = kDefaults.samples;
  double bias = kDefaults.depth_bias, tolerance = kDefaults.depth_tolerance, threshold = kDefaults.angle_threshold;
  bool no_visibility = !kDefaults.visibility, proxy_depth = false;
};
void add_fuse_options(CLI::App& app, FuseOpts& o);
ibl::fusion::FuseDesc fuse_desc(const FuseOpts& o);
// Loads a probe set with a progress bar; prints its warnings on stderr.
ibl::fusion::ProbeSet load_probes_cli(const std::string& path, bool proxy_depth);
// Adds `fuse eval` (cmd_fuse_eval.cpp).
void setup_eval(CLI::App& fuse);

}  // namespace iblcli
