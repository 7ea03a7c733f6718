#include "iblkit/core/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "iblkit/core/error.h"

namespace ibl {

namespace fs = std::filesystem;

namespace {

// The registry of live temporary files, readable from a signal handler: fixed slots, no allocation,
// no locks. A slot is claimed (Free → Writing), filled, published (→ Live) and freed (→ Free) by its
// AtomicFile; `generation` changes on every claim, so a handler that copied a path while the slot
// was reused sees the change and leaves the copy alone. Paths longer than a slot are not registered
// (their temporary file survives a signal, as does one made while all slots are taken).
constexpr int kSlots = 256;
constexpr size_t kSlotPath = 1024;
enum SlotState : int { Free = 0, Writing = 1, Live = 2 };
struct Slot {
  std::atomic<int> state{Free};
  std::atomic<unsigned> generation{0};
  char path[kSlotPath];
};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<unsigned>::is_always_lock_free);
Slot g_slots[kSlots];

int register_temp(const std::string& path) {
  if (path.size() >= kSlotPath) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = Free;
    if (!g_slots[i].state.compare_exchange_strong(expected, Writing)) continue;
    g_slots[i].generation.fetch_add(1);
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    g_slots[i].state.store(Live);
    return i;
  }
  return -1;
}

void unregister_temp(int slot) {
  if (slot >= 0) g_slots[slot].state.store(Free);
}

std::atomic<unsigned> g_counter{0};

std::string reason(int err) { return err ? std::strerror(err) : "unknown error"; }

extern "C" void on_fatal_signal(int sig) {
  remove_live_temp_files();
  // Die of the signal as without the handler: the default action, delivered when this returns.
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

void remove_live_temp_files() noexcept {
  char copy[kSlotPath];
  for (auto& s : g_slots) {
    if (s.state.load() != Live) continue;
    unsigned g = s.generation.load();
    std::memcpy(copy, s.path, kSlotPath);
    copy[kSlotPath - 1] = '\0';
    if (s.state.load() == Live && s.generation.load() == g) ::unlink(copy);
  }
}

void remove_temp_files_on_signals() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    ::sigaction(sig, &sa, nullptr);
  }
}

AtomicFile::AtomicFile(const std::string& path) : path_(path), target_(path) {
  std::error_code ec;
  auto st = fs::symlink_status(path, ec);
  if (!ec && fs::is_symlink(st)) {
    auto real = fs::canonical(path, ec);
    if (!ec) target_ = real.string();
    st = fs::status(target_, ec);
  }
  if (!ec && fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st)) {
    direct_ = true;  // a device or FIFO: written in place, never replaced
    temp_ = path;
    return;
  }
  fs::path p(target_);
  std::string name = p.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter.fetch_add(1)) +
                     p.extension().string();
  temp_ = (p.parent_path() / name).string();
  slot_ = register_temp(temp_);
}

AtomicFile::~AtomicFile() {
  if (!committed_ && !direct_) ::unlink(temp_.c_str());
  unregister_temp(slot_);
}

void AtomicFile::commit() {
  if (committed_) fail(ErrorKind::Internal, "{}: committed twice", path_);
  if (direct_) {
    committed_ = true;
    return;
  }
  if (std::rename(temp_.c_str(), target_.c_str()) != 0) {
    int err = errno;
    ::unlink(temp_.c_str());
    fail(ErrorKind::Io, "{}: cannot write ({})", path_, reason(err));
  }
  committed_ = true;
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  AtomicFile f(path);
  std::FILE* out = std::fopen(f.temp_path().c_str(), "wb");
  if (!out) fail(ErrorKind::Io, "{}: cannot write ({})", path, reason(errno));
  errno = 0;
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size() && std::fflush(out) == 0;
  int err = errno;
  ok = std::fclose(out) == 0 && ok;
  if (!ok) fail(ErrorKind::Io, "{}: cannot write ({})", path, reason(err ? err : errno));
  f.commit();
}

}  // namespace ibl
