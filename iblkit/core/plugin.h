// Optional parts with heavy dependencies — OpenImageIO (image formats iblkit does not read itself,
// text in pictures), OpenVDB, Embree/assimp/OpenGL — can live in plugins: shared libraries
// libiblkit_<name>.so in the folder of the running executable, loaded the first time they are needed,
// so that a command pays only for what it uses (docs/startup.md).
//
// The library's code is the same whether a part is linked into the program (the test binary and the
// benchmarks link everything) or sits in a plugin (the iblkit command): the part hands what it
// provides to a Provided<T> slot from a static registrar that runs when its code is loaded, and the
// code that needs it calls slot.get(), which loads the plugin only when nothing was provided yet.
#pragma once
#include <atomic>
#include <string>

#include "iblkit/core/error.h"

namespace ibl::plugin {

// The file load(name) opens: <folder of the running executable>/libiblkit_<name>.so.
std::string path_of(const std::string& name);

// Loads plugin `name` unless it is loaded already (thread-safe). Throws Error(Unsupported) with one
// line naming the file and the loader's reason when it cannot be loaded.
void load(const std::string& name);

// Whether load(name) would find a file to open.
bool present(const std::string& name);

// A slot for what one part provides (a table of functions, say). Constant-initialised, so a
// registrar may fill it from any static initialiser; reads are lock-free.
template <typename T>
class Provided {
 public:
  // `plugin`: the plugin whose loading fills this slot; `what`: the part, for messages.
  constexpr Provided(const char* plugin, const char* what) : plugin_(plugin), what_(what) {}

  void provide(const T* p) { p_.store(p, std::memory_order_release); }
  // What was provided, or nullptr (never loads anything).
  const T* find() const { return p_.load(std::memory_order_acquire); }
  // What was provided, loading the plugin first when needed.
  const T& get() const {
    if (const T* p = find()) return *p;
    load(plugin_);
    if (const T* p = find()) return *p;
    fail(ErrorKind::Internal, "plugin {} loaded but provides no {}", path_of(plugin_), what_);
  }

 private:
  std::atomic<const T*> p_{nullptr};
  const char* plugin_;
  const char* what_;
};

}  // namespace ibl::plugin
