#include "cli.h"

#include <sys/stat.h>
#include <unistd.h>
#include <cmath>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>

#include <fmt/format.h>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"

namespace iblcli {

namespace fs = std::filesystem;

Globals& globals() {
  static Globals g;
  return g;
}

std::vector<CommandEntry>& command_registry() {
  static std::vector<CommandEntry> r;
  return r;
}
Command::Command(std::string name, Setup setup) { command_registry().push_back({std::move(name), std::move(setup)}); }

std::vector<DemoEntry>& demo_registry() {
  static std::vector<DemoEntry> r;
  return r;
}
DemoStep::DemoStep(std::string name, int order, Fn fn) {
  demo_registry().push_back({std::move(name), order, std::move(fn)});
}

namespace {
struct Bar {
  std::mutex mu;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last{};
  std::string stage;
  bool drawn = false;
};
Bar& bar() {
  static Bar b;
  return b;
}
}  // namespace

ibl::ProgressFn progress_bar() { return progress_bar(isatty(STDERR_FILENO)); }

ibl::ProgressFn progress_bar(bool terminal) {
  if (globals().quiet) return {};
  bar().start = std::chrono::steady_clock::now();
  bar().last = {};
  if (!terminal)  // a log, not a terminal: a line every few seconds once the work takes that long
    return [](std::string_view stage, double f) {
      Bar& b = bar();
      std::lock_guard<std::mutex> lock(b.mu);
      auto now = std::chrono::steady_clock::now();
      // A line per 5 s: readable in a log, no flood (IBLKIT_PROGRESS_EVERY=seconds for tests).
      static const auto kEvery =
          std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(
              std::getenv("IBLKIT_PROGRESS_EVERY") ? std::atof(std::getenv("IBLKIT_PROGRESS_EVERY")) : 5.0));
      if (now - b.start < kEvery || (b.last.time_since_epoch().count() != 0 && now - b.last < kEvery)) return;
      b.last = now;
      std::fprintf(stderr, "iblkit: %s %d%% (%.0f s)\n", std::string(stage).c_str(),
                   static_cast<int>(std::clamp(f, 0.0, 1.0) * 100),
                   std::chrono::duration<double>(now - b.start).count());
    };
  return [](std::string_view stage, double f) {
    Bar& b = bar();
    std::lock_guard<std::mutex> lock(b.mu);
    auto now = std::chrono::steady_clock::now();
    // Only for work longer than a second, and at most 20 redraws a second.
    if (now - b.start < std::chrono::seconds(1)) return;
    if (stage == b.stage && now - b.last < std::chrono::milliseconds(50) && f < 1.0) return;
    b.last = now;
    b.stage = std::string(stage);
    int width = 30, filled = static_cast<int>(std::clamp(f, 0.0, 1.0) * width);
    std::fprintf(stderr, "\r%-24.24s [%s%s] %3d%%", std::string(stage).c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), static_cast<int>(f * 100));
    std::fflush(stderr);
    b.drawn = true;
  };
}

void progress_done() {
  Bar& b = bar();
  std::lock_guard<std::mutex> lock(b.mu);
  if (b.drawn) std::fprintf(stderr, "\r%-70s\r", "");
  b.drawn = false;
  b.stage.clear();
}

void emit(const nlohmann::json& j, const std::function<void()>& table) {
  if (globals().json) {
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    table();
  }
}

void info(const std::string& msg) {
  if (!globals().quiet) std::fprintf(stderr, "%s\n", msg.c_str());
}

ibl::Vec3 parse_vec3(const std::string& s, const std::string& what) {
  ibl::Vec3 v;
  std::stringstream ss(s);
  std::string part;
  int i = 0;
  while (std::getline(ss, part, ',')) {
    if (i >= 3) break;
    try {
      size_t used = 0;
      v[i] = std::stod(part, &used);
      if (used != part.size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      ibl::fail(ibl::ErrorKind::Value, "{} '{}': expected three numbers x,y,z", what, s);
    }
    ++i;
  }
  if (i != 3 || std::getline(ss, part, ','))
    ibl::fail(ibl::ErrorKind::Value, "{} '{}': expected three numbers x,y,z", what, s);
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    ibl::fail(ibl::ErrorKind::Value, "{} '{}': the numbers must be finite", what, s);
  return v;
}

std::vector<double> parse_double_list(const std::string& s, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ',')) {
    size_t used = 0;
    double x = 0;
    try {
      x = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || !std::isfinite(x))
      ibl::fail(ibl::ErrorKind::Value, "{}: \"{}\" is not a list of numbers", what, s);
    v.push_back(x);
  }
  return v;
}

std::vector<int> parse_int_list(const std::string& s, const std::string& what) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stoi(part, &used));
      if (used != part.size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      ibl::fail(ibl::ErrorKind::Value, "{} '{}': expected whole numbers separated by commas", what, s);
    }
  }
  if (out.empty()) ibl::fail(ibl::ErrorKind::Value, "{} is empty", what);
  return out;
}

ibl::io::EnvReadDesc& add_probe_read_options(CLI::App& app) {
  auto* desc = iblcli::app_owned<ibl::io::EnvReadDesc>();  // lives as long as the app (the process)
  auto* mapping = iblcli::app_owned<std::string>();
  app.add_option("--in-mapping", *mapping,
                 "mapping of the input (latlong, mirrorball, angular, hcross, vcross, cubestrip, octahedral); "
                 "default: detected from the image shape and name")
      ->each([desc](const std::string& s) { desc->mapping = ibl::sphere::parse_mapping(s); });
  app.add_option("--dead-angle", desc->dead_angle_deg, "mirror ball: unusable cone behind the ball, degrees")
      ->check(CLI::Range(0.0, 89.0));
  app.add_flag("--sanitize", desc->sanitize,
               "replace NaN/Inf/negative pixels by 0 (and say how many) instead of failing");
  return *desc;
}

std::vector<std::pair<std::string, std::string>> describe_options(const CLI::App& app) {
  std::string path = app.get_name();
  for (const CLI::App* p = app.get_parent(); p && p->get_parent(); p = p->get_parent())
    path = p->get_name() + " " + path;
  std::vector<std::pair<std::string, std::string>> d{{"the subcommand", path}};
  for (const CLI::Option* o : app.get_options()) {
    if (o->get_name() == "--help" || o->get_name() == "-h") continue;
    std::string v;
    if (o->count() == 0) {
      v = o->get_default_str().empty() ? "(not given)" : o->get_default_str();
    } else {
      for (const auto& r : o->results()) v += (v.empty() ? "" : " ") + r;
      if (v.empty()) v = "(given)";  // a flag
    }
    d.push_back({o->get_name(), v});
  }
  return d;
}

namespace {
std::map<const CLI::App*, std::vector<std::string>>& extra_outputs() {
  static std::map<const CLI::App*, std::vector<std::string>> m;
  return m;
}
bool is_output(const CLI::App& app, const CLI::Option* o) {
  if (o->check_name("--out") || o->check_name("output")) return true;
  auto it = extra_outputs().find(&app);
  if (it == extra_outputs().end()) return false;
  return std::any_of(it->second.begin(), it->second.end(), [&](const std::string& n) { return o->check_name(n); });
}
}  // namespace

void outputs(CLI::App& app, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (!app.get_option_no_throw(n))
      ibl::fail(ibl::ErrorKind::Internal, "iblcli::outputs: {} has no option {}", app.get_name(), n);
    extra_outputs()[&app].push_back(n);
  }
}

void check_outputs(const CLI::App& app) {
  struct File {
    std::string option, path;
    dev_t dev;
    ino_t ino;
  };
  std::vector<File> ins, outs;
  std::vector<std::pair<std::string, std::string>> new_outs;  // (option, absolute path) of outputs not there yet
  for (const CLI::Option* o : app.get_options()) {
    const bool out = is_output(app, o);
    std::vector<std::string> values = o->results();
    if (o->count() == 0) {
      if (!out || o->get_default_str().empty()) continue;
      values = {o->get_default_str()};  // a default output is written too
    }
    for (const std::string& v : values) {
      if (v.empty()) continue;
      struct stat st {};
      if (out) {
        // The output as it will be replaced: a link itself (core/atomic_file.h replaces links).
        if (::lstat(v.c_str(), &st) == 0)
          outs.push_back({o->get_name(), v, st.st_dev, st.st_ino});
        else
          new_outs.push_back({o->get_name(), fs::absolute(v).lexically_normal().string()});
      } else if (::stat(v.c_str(), &st) == 0 && (S_ISREG(st.st_mode) || S_ISDIR(st.st_mode))) {
        ins.push_back({o->get_name(), v, st.st_dev, st.st_ino});
        if (S_ISREG(st.st_mode)) ibl::note_input_file(v);
      }
    }
  }
  // "--out X" for an option, "X" for a positional.
  auto named = [](const File& f) { return f.option.rfind("-", 0) == 0 ? f.option + " " + f.path : f.path; };
  for (size_t i = 0; i < outs.size(); ++i) {
    for (const File& in : ins)
      if (in.dev == outs[i].dev && in.ino == outs[i].ino)
        ibl::fail(ibl::ErrorKind::Value,
                  "{}: is the same file as the input {}; write the output elsewhere (nothing was written)",
                  named(outs[i]), named(in));
    for (size_t k = 0; k < i; ++k)
      if (outs[k].dev == outs[i].dev && outs[k].ino == outs[i].ino)
        ibl::fail(ibl::ErrorKind::Value, "{} and {} name the same file: give each output its own path", named(outs[k]),
                  named(outs[i]));
  }
  for (size_t i = 0; i < new_outs.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (new_outs[k].second == new_outs[i].second)
        ibl::fail(ibl::ErrorKind::Value, "{} and {} name the same file {}: give each output its own path",
                  new_outs[k].first, new_outs[i].first, new_outs[i].second);
}

std::string default_probe() {
  const char* candidates[] = {
      "/usr/share/blender/datafiles/studiolights/world/forest.exr",
      IBLKIT_SOURCE_DIR "/../shared/probes/ict/grace_latlong_256.hdr",
  };
  for (const char* c : candidates)
    if (fs::exists(c)) return c;
  ibl::fail(ibl::ErrorKind::Io,
            "no built-in probe found: install Debian's blender-data (scripts/install-deps) or pass a probe file");
}

std::string unknown_subcommand(CLI::App& app, int argc, char** argv) {
  CLI::App* cur = &app;
  std::string path = "iblkit";
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a.empty() || a[0] == '-') continue;
    if (cur->get_subcommands({}).empty()) return "";  // a leaf: the rest are its arguments
    CLI::App* sub = nullptr;
    for (CLI::App* s : cur->get_subcommands({}))
      if (s->get_name() == a) sub = s;
    if (!sub) return fmt::format("unknown subcommand '{}' of {} (see {} --help)", a, path, path);
    cur = sub;
    path += " " + a;
  }
  return "";
}

namespace {
// The subcommand that ran: the deepest parsed one.
CLI::App* ran(CLI::App& app) {
  CLI::App* cur = &app;
  for (bool more = true; more;) {
    more = false;
    for (CLI::App* s : cur->get_subcommands()) {
      cur = s;
      more = true;
      break;
    }
  }
  return cur;
}
void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (size_t k = s.find(from); k != std::string::npos; k = s.find(from, k + to.size())) s.replace(k, from.size(), to);
}
}  // namespace

std::string size_options(CLI::App& app) {
  static const char* kSizeWords[] = {"size", "grid", "samples", "memory", "resolution", "rays", "bands", "frames"};
  std::string out;
  for (const CLI::Option* o : ran(app)->get_options()) {
    if (o->count() == 0 || o->get_name().rfind("--", 0) != 0) continue;
    const std::string n = o->get_name();
    if (std::none_of(std::begin(kSizeWords), std::end(kSizeWords),
                     [&](const char* w) { return n.find(w) != std::string::npos; }))
      continue;
    std::string v;
    for (const auto& r : o->results()) v += (v.empty() ? "" : " ") + r;
    out += (out.empty() ? "" : ", ") + n + " " + v;
  }
  return out;
}

std::string for_command(CLI::App& app, const std::string& message) {
  std::string m = message;
  // Out of memory: which of the options given sets the size to lower.
  if (m.find("out of memory") != std::string::npos || m.find("would allocate") != std::string::npos) {
    const std::string sizes = size_options(app);
    if (!sizes.empty()) m += fmt::format(" (lower {})", sizes);
  }
  const bool has_sanitize = ran(app)->get_option_no_throw("--sanitize") != nullptr;
  if (has_sanitize) {
    replace_all(m, "with sanitize replaces", "with --sanitize replaces");
    replace_all(m, "; sanitize replaces", "; --sanitize replaces");
  } else {
    replace_all(m, " (reading it with sanitize replaces such values by 0)", "");
    replace_all(m, "; sanitize replaces such values by 0", "");
  }
  return m;
}

}  // namespace iblcli
