#include "iblkit/core/atomic_file.h"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <unordered_set>
#include <utility>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/core/input_file.h"

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

void roll_back_open_transaction() noexcept;

extern "C" void on_fatal_signal(int sig) {
  remove_live_temp_files();
  roll_back_open_transaction();
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

// ---- OutputTransaction ----------------------------------------------------------------------------
// Its entries are readable from a signal handler: chunks of fixed-size entries, each entry filled
// before the chunk's count is raised (release), chunks linked once and never freed while the
// transaction is open. Paths longer than an entry's buffers are committed outside the transaction.

struct TxEntry {
  char target[kSlotPath];
  char backup[kSlotPath];  // "" where there was no file to keep
  bool existed;            // a file was there (kept in backup, unless keeping it failed)
};
struct TxChunk {
  static constexpr int kEntries = 64;
  TxEntry e[kEntries];
  std::atomic<int> used{0};
  std::atomic<TxChunk*> next{nullptr};
};
constexpr int kTxFolders = 256;

struct OutputTransaction::State {
  TxChunk head;
  TxChunk* tail = &head;
  char folders[kTxFolders][kSlotPath];  // created by make_output_folders, in order
  std::atomic<int> folder_count{0};
  std::mutex mutex;  // writers on several threads
  std::unordered_set<std::string> targets;
  size_t files = 0;
  std::map<std::pair<dev_t, ino_t>, std::string> inputs;  // files the command reads (note_input_file)
  std::set<std::pair<dev_t, ino_t>> written;              // files the command wrote (never inputs)
  ~State() {
    for (TxChunk* c = head.next.load(); c;) {
      TxChunk* n = c->next.load();
      delete c;
      c = n;
    }
  }
};

namespace {

std::atomic<OutputTransaction::State*> g_tx{nullptr};

// Puts back every replaced file, removes every new one and then the created folders (deepest first;
// a folder that is not empty stays). Async-signal-safe: unlink, rename, rmdir on prepared paths.
void roll_back(OutputTransaction::State& st) noexcept {
  for (TxChunk* c = &st.head; c; c = c->next.load(std::memory_order_acquire)) {
    int n = c->used.load(std::memory_order_acquire);
    for (int i = 0; i < n; ++i) {
      const TxEntry& e = c->e[i];
      if (e.backup[0])
        ::rename(e.backup, e.target);
      else if (!e.existed)
        ::unlink(e.target);
    }
  }
  for (int i = st.folder_count.load(std::memory_order_acquire) - 1; i >= 0; --i) ::rmdir(st.folders[i]);
}

void roll_back_open_transaction() noexcept {
  if (auto* st = g_tx.exchange(nullptr)) roll_back(*st);
}

// Keeps the file at `target` (if any) beside it and notes the entry, before the new file is renamed
// onto it. Returns false where the transaction cannot take the path (too long): committed as without one.
bool note_replacement(OutputTransaction::State& st, const std::string& target) {
  if (target.size() >= kSlotPath) return false;
  std::lock_guard<std::mutex> lock(st.mutex);
  if (!st.targets.insert(target).second) return true;  // already noted: its first state is what comes back
  if (st.tail->used.load() == TxChunk::kEntries) {
    auto* c = new TxChunk;
    st.tail->next.store(c, std::memory_order_release);
    st.tail = c;
  }
  TxEntry& e = st.tail->e[st.tail->used.load()];
  std::memcpy(e.target, target.c_str(), target.size() + 1);
  e.backup[0] = '\0';
  std::error_code ec;
  e.existed = fs::exists(fs::symlink_status(target, ec));
  if (e.existed && fs::is_regular_file(fs::status(target, ec))) {
    fs::path p(target);
    std::string b = (p.parent_path() / (p.stem().string() + ".bak-" + std::to_string(::getpid()) + "-" +
                                        std::to_string(g_counter.fetch_add(1)) + p.extension().string()))
                        .string();
    if (b.size() < kSlotPath) {
      bool kept = ::link(target.c_str(), b.c_str()) == 0;
      if (!kept) kept = fs::copy_file(target, b, ec) && !ec;  // a file system without hard links
      if (kept) std::memcpy(e.backup, b.c_str(), b.size() + 1);
    }
  }
  st.tail->used.fetch_add(1, std::memory_order_release);
  ++st.files;
  return true;
}

}  // namespace

OutputTransaction::OutputTransaction() : state_(new State) {
  State* expected = nullptr;
  if (!g_tx.compare_exchange_strong(expected, state_)) {
    delete state_;
    state_ = nullptr;
    fail(ErrorKind::Internal, "an output transaction is open already");
  }
}

OutputTransaction::~OutputTransaction() {
  if (!state_) return;
  State* expected = state_;
  if (g_tx.compare_exchange_strong(expected, nullptr)) roll_back(*state_);  // (a signal may have done it)
  delete state_;
}

void OutputTransaction::commit() {
  if (!state_) fail(ErrorKind::Internal, "output transaction committed twice");
  g_tx.store(nullptr);
  for (TxChunk* c = &state_->head; c; c = c->next.load())
    for (int i = 0, n = c->used.load(); i < n; ++i)
      if (c->e[i].backup[0]) ::unlink(c->e[i].backup);
  delete state_;
  state_ = nullptr;
}

size_t OutputTransaction::files() const {
  if (!state_) return 0;
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->files;
}

void make_output_folders(const std::string& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::path p = fs::path(dir).lexically_normal();
  if (p.has_filename() == false && p.has_parent_path()) p = p.parent_path();  // "faces/" → "faces"
  if (fs::is_directory(p, ec)) return;
  // The missing levels, outermost first.
  std::vector<fs::path> missing;
  for (fs::path q = p; !q.empty(); q = q.parent_path()) {
    auto st = fs::status(q, ec);
    if (fs::exists(st)) {
      if (!fs::is_directory(st)) fail(ErrorKind::Io, "{}: cannot create folder ({} is not a folder)", dir, q.string());
      break;
    }
    missing.push_back(q);
    if (q == q.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (::mkdir(it->c_str(), 0777) != 0) {
      int err = errno;
      if (err == EEXIST && fs::is_directory(*it, ec)) continue;  // made meanwhile by another writer
      fail(ErrorKind::Io, "{}: cannot create folder ({})", it->string(), reason(err));
    }
    if (auto* st = g_tx.load()) {
      std::lock_guard<std::mutex> lock(st->mutex);
      int n = st->folder_count.load();
      if (n < kTxFolders && it->string().size() < kSlotPath) {
        std::memcpy(st->folders[n], it->c_str(), it->string().size() + 1);
        st->folder_count.store(n + 1, std::memory_order_release);
      }
    }
  }
}

AtomicFile::AtomicFile(const std::string& path) : path_(path), target_(path) {
  // target_ is path itself, a link included: the rename replaces the link, never its target.
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) {
    if (S_ISBLK(st.st_mode)) fail(ErrorKind::Io, "{}: cannot write (it is a block device; iblkit writes files)", path);
    direct_ = true;  // a FIFO, socket or character device (/dev/null, /dev/stdout): written in place
    temp_ = path;
    return;
  }
  fs::path p(target_);
  if (!p.parent_path().empty()) {
    try {
      make_output_folders(p.parent_path().string());
    } catch (const Error& e) {
      fail(ErrorKind::Io, "{}: cannot write ({})", path_, e.what());
    }
  }
  std::string name = p.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(g_counter.fetch_add(1)) + p.extension().string();
  temp_ = (p.parent_path() / name).string();
  slot_ = register_temp(temp_);
}

AtomicFile::~AtomicFile() {
  if (!committed_ && !direct_) ::unlink(temp_.c_str());
  unregister_temp(slot_);
}

Error AtomicFile::naming_path(const Error& e) const {
  std::string msg = e.what();
  if (!temp_.empty() && temp_ != path_)
    for (size_t at = 0; (at = msg.find(temp_, at)) != std::string::npos; at += path_.size())
      msg.replace(at, temp_.size(), path_);
  return Error(e.kind(), msg);
}

void AtomicFile::commit() {
  if (committed_) fail(ErrorKind::Internal, "{}: committed twice", path_);
  if (direct_) {
    committed_ = true;
    return;
  }
  auto* tx = g_tx.load();
  if (tx) {
    struct stat st {};
    if (::lstat(target_.c_str(), &st) == 0) {
      std::lock_guard<std::mutex> lock(tx->mutex);
      auto id = std::make_pair(st.st_dev, st.st_ino);
      auto in = tx->inputs.find(id);
      if (in != tx->inputs.end() && !tx->written.count(id)) {
        ::unlink(temp_.c_str());
        fail(ErrorKind::Value,
             "{}: is an input of this command ({}); write the output elsewhere (the input is left as it was)", path_,
             in->second);
      }
    }
    note_replacement(*tx, target_);
  }
  if (std::rename(temp_.c_str(), target_.c_str()) != 0) {
    int err = errno;
    ::unlink(temp_.c_str());
    fail(ErrorKind::Io, "{}: cannot write ({})", path_, reason(err));
  }
  committed_ = true;
  if (tx) {
    struct stat st {};
    if (::lstat(target_.c_str(), &st) == 0) {
      std::lock_guard<std::mutex> lock(tx->mutex);
      tx->written.insert({st.st_dev, st.st_ino});
    }
  }
}

void note_input_file(const std::string& path) {
  auto* tx = g_tx.load();
  struct stat st {};
  if (!tx || ::stat(path.c_str(), &st) != 0) return;
  std::lock_guard<std::mutex> lock(tx->mutex);
  auto id = std::make_pair(st.st_dev, st.st_ino);
  if (!tx->written.count(id)) tx->inputs.emplace(id, path);
}

void copy_file_atomically(const std::string& from, const std::string& to) {
  require_input_file(from);
  AtomicFile f(to);
  std::error_code ec;
  if (!f.temp_path().empty() && f.temp_path() != to) {
    fs::copy_file(from, f.temp_path(), fs::copy_options::overwrite_existing, ec);
  } else {
    fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);  // a FIFO or device: in place
  }
  if (ec) fail(ErrorKind::Io, "{}: cannot copy to {} ({})", from, to, ec.message());
  f.commit();
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
