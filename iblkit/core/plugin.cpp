#include "iblkit/core/plugin.h"

#include <dlfcn.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <mutex>

namespace ibl::plugin {

namespace fs = std::filesystem;

namespace {
fs::path exe_dir() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) fail(ErrorKind::Unsupported, "cannot find the running executable (/proc/self/exe: {})", ec.message());
  return exe.parent_path();
}
}  // namespace

std::string path_of(const std::string& name) { return (exe_dir() / ("libiblkit_" + name + ".so")).string(); }

bool present(const std::string& name) {
  std::error_code ec;
  return fs::exists(path_of(name), ec);
}

void load(const std::string& name) {
  static std::mutex mu;
  static std::map<std::string, void*> loaded;
  std::lock_guard<std::mutex> lock(mu);
  if (loaded.count(name)) return;
  std::string path = path_of(name);
  std::error_code ec;
  if (!fs::exists(path, ec))
    fail(ErrorKind::Unsupported, "{}: plugin not found (it is built beside the iblkit executable; rebuild iblkit)",
         path);
  // RTLD_NOW: a plugin that does not match this executable fails here, not half-way through a command.
  // The handle is kept for the process's life: its registrars filled slots that point into it.
  void* h = ::dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (!h) {
    const char* err = ::dlerror();
    fail(ErrorKind::Unsupported, "cannot load plugin {} ({})", path, err ? err : "unknown reason");
  }
  loaded[name] = h;
}

}  // namespace ibl::plugin
