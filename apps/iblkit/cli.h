// Shared pieces of the iblkit command-line tool: subcommand registration, demo steps, output
// (tables or --json), a progress bar, and argument parsers for vectors and mappings.
#pragma once
#include <deque>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/io/envmap_io.h"

namespace iblcli {

// A T made for the whole run and freed at exit: the option structs that setup() functions bind to
// CLI11 options and capture in their callbacks (plain `new` made every run a leak to LeakSanitizer,
// so make test-sanitize failed every CLI test).
template <typename T, typename... Args>
T* app_owned(Args&&... args) {
  static std::deque<std::unique_ptr<T>> kept;
  kept.push_back(std::make_unique<T>(std::forward<Args>(args)...));
  return kept.back().get();
}

// Options every subcommand shares.
struct Globals {
  bool json = false;   // print machine-readable JSON on stdout instead of tables
  bool quiet = false;  // no progress bar, no chatter on stderr
};
Globals& globals();

// A subcommand registers its setup from its own file:
//   static iblcli::Command reg("sh", setup_fn);
// setup_fn adds options to the CLI11 sub-app and sets its callback. Its name, description and
// place in --help are listed in main.cpp, which prints them without loading any plugin.
struct Command {
  using Setup = std::function<void(CLI::App&)>;
  Command(std::string name, Setup setup);
};
struct CommandEntry {
  std::string name;
  Command::Setup setup;
};
std::vector<CommandEntry>& command_registry();

// A step of `iblkit demo`, registered by the module's command file; steps run in `order`.
struct DemoContext {
  std::string out_dir;                                        // folder for pictures and numbers
  std::string probe;                                          // the real probe the demo starts from
  nlohmann::json summary;                                     // numbers each step adds; written to OUT/summary.json
  std::vector<std::pair<std::string, std::string>> pictures;  // (caption, png path) for the contact sheet
};
struct DemoStep {
  using Fn = std::function<void(DemoContext&)>;
  DemoStep(std::string name, int order, Fn fn);
};
struct DemoEntry {
  std::string name;
  int order;
  DemoStep::Fn fn;
};
std::vector<DemoEntry>& demo_registry();

// A progress callback that draws a bar on stderr when it is a terminal and not --quiet.
ibl::ProgressFn progress_bar();
// … when `terminal` (the caller knows where stderr ends up: an MPI rank's goes through mpirun) and not --quiet.
ibl::ProgressFn progress_bar(bool terminal);
// Ends the bar line (call when the work is done).
void progress_done();

// Outputs and inputs (docs/cli.md, "Outputs"): before a subcommand runs, main.cpp calls
// check_outputs on it. The options "--out" (with "-o") and the positional "output" are outputs of
// every subcommand; a subcommand with other outputs names them once in its setup:
//   iblcli::outputs(app, {"--layers", "--mask"});
// Every other option or positional value that names an existing file or folder is an input.
void outputs(CLI::App& app, std::initializer_list<const char*> names);
// Refuses (one line, nothing written) an output that is the same file (device and inode) as an input
// or as another output, and notes every input in the open OutputTransaction, whose commits then never
// replace one (core/atomic_file.h; files the readers open are noted there too).
void check_outputs(const CLI::App& app);

// Prints a result: JSON when --json, else the table callback writes human text.
void emit(const nlohmann::json& j, const std::function<void()>& table);
// A line of chatter on stderr (suppressed by --quiet).
void info(const std::string& msg);

// Parsers for option values.
ibl::Vec3 parse_vec3(const std::string& s, const std::string& what);             // "x,y,z"
std::vector<int> parse_int_list(const std::string& s, const std::string& what);  // "1,2,4"
// "0.5,90,1e-3": finite numbers separated by commas (an empty string gives none).
std::vector<double> parse_double_list(const std::string& s, const std::string& what);
// Adds --mapping, --dead-angle, --sanitize to an app and returns the read settings they fill.
ibl::io::EnvReadDesc& add_probe_read_options(CLI::App& app);

// When argv names a subcommand that does not exist ("iblkit bogus", "iblkit lab bogus"), the message
// "unknown subcommand 'bogus' of iblkit lab (see iblkit lab --help)"; else "".
std::string unknown_subcommand(CLI::App& app, int argc, char** argv);
// A library message as the user of this command line should read it: the library's parameter hints
// ("sanitize replaces such values by 0") become the flag the command that ran has ("--sanitize …"),
// or are dropped where it has none.
std::string for_command(CLI::App& app, const std::string& message);

// The command line of the subcommand that runs: its path ("ilf build") and every option's and
// positional's name with its value as given (or its default), for the ranks of an MPI job to compare.
std::vector<std::pair<std::string, std::string>> describe_options(const CLI::App& app);

// The options of the subcommand that ran which set how much it allocates (sizes, grids, samples,
// memory), as given: "--size 16384, --samples 4", or "" when none was given.
std::string size_options(CLI::App& app);

// Path of a real probe to use when none is given: blender-data's, else shared/probes.
std::string default_probe();

}  // namespace iblcli
