// Output files written whole or not at all (docs/formats.md, "How every output is written"): every writer puts its
// bytes into a temporary file beside the output and renames it into place once it is complete and closed, so a failed
// or killed command never leaves a half-written file at its output path, and the file that was there before stays
// intact until the new one replaces it in one step. (Protection against crashes of the process, not of the machine:
// nothing is fsync'ed.)
//
//   AtomicFile f(path);                     // nothing created yet
//   write_somehow(f.temp_path());           // e.g. "out/probe.tmp-4711-3.exr"; throws on failure
//   f.commit();                             // rename into place; without it the destructor removes the temp
#pragma once
#include <string>
#include <string_view>

namespace ibl {

class Error;

class AtomicFile {
 public:
  // Chooses temp_path() beside `path` as "<stem>.tmp-<pid>-<n><extension>": unique in the process
  // and across processes, and with the output's extension so a writer that picks its format by
  // extension still can. Where `path` is a symbolic link, the link is replaced, never its target (a
  // link planted in an output folder cannot make a command write outside it). Where `path` is (or
  // links to) a FIFO, a socket or a character device (/dev/null, /dev/stdout), temp_path() is that
  // itself and commit() does nothing; a block device is refused.
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();  // removes temp_path() unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_; }
  // Renames temp_path() onto path(); on failure removes temp_path() and throws ErrorKind::Io
  // "PATH: cannot write (reason)".
  void commit();
  // `e` with every mention of temp_path() replaced by path(): a writer handed temp_path() names the
  // temporary in its messages, the user named path(). `catch (const Error& e) { throw f.naming_path(e); }`
  Error naming_path(const Error& e) const;

 private:
  std::string path_, target_, temp_;
  int slot_ = -1;  // in the registry of live temporary files (remove_live_temp_files), or -1
  bool direct_ = false, committed_ = false;
};

// Writes `bytes` to `path` through an AtomicFile; ErrorKind::Io "PATH: cannot write (reason)".
void write_file_atomically(const std::string& path, std::string_view bytes);
// Copies file `from` to `to` through an AtomicFile (a link at `to` is replaced, not written through).
void copy_file_atomically(const std::string& from, const std::string& to);

// Notes `path` (followed through links) as an input of the command while an OutputTransaction is open
// (require_input_file does, for every file a reader opens; the CLI does for every file its options
// name): from then on no AtomicFile of the command replaces that file (same device and inode), its
// commit() fails "OUT: is an input of this command (IN); …" and the input stays as it was. Files
// the command wrote itself are not inputs. Without an open transaction it does nothing.
void note_input_file(const std::string& path);

// Removes the temporary file of every AtomicFile alive in this process. Async-signal-safe: for a
// signal handler.
void remove_live_temp_files() noexcept;

// For programs (the CLI calls it first thing; the library never does): on SIGINT, SIGTERM and
// SIGHUP, remove_live_temp_files(), roll back the open OutputTransaction, and then die of the signal
// as without the handler. A signal the process ignores (nohup, a shell's background job) stays ignored.
void remove_temp_files_on_signals();

// A command's outputs as one ("a command that fails after writing one of several outputs
// removes what it wrote"). While a transaction is open, AtomicFile::commit() still renames each file
// into place at once (so the command can read back what it wrote: a capture's frames, cached depth
// maps), but first keeps the file it replaces as a hard link beside it ("<stem>.bak-<pid>-<n><ext>"),
// and make_output_folders() notes the folders it creates. commit() drops the kept files. Destroying
// an uncommitted transaction (the command threw), or a signal while it is open, puts every replaced
// file back, removes every new file, and removes the folders it created once they are empty: the
// outputs are as before the command. One transaction at a time per process (the CLI opens one
// around each subcommand; the library never opens one).
//
//   OutputTransaction tx;        // AtomicFile commits from now on are provisional
//   run_the_command();           // throws → ~OutputTransaction rolls everything back
//   tx.commit();                 // keep every output
class OutputTransaction {
 public:
  OutputTransaction();   // ErrorKind::Internal if one is open already
  ~OutputTransaction();  // rolls back unless committed
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  void commit();
  // Files renamed into place so far (for tests and messages).
  size_t files() const;

  struct State;

 private:
  State* state_;
};

// Creates `dir` and its missing parents (like mkdir -p), noting each folder it creates in the open
// OutputTransaction. The one rule for output folders (docs/cli.md, "Outputs"): every command creates
// the missing folders of its outputs, files and folders alike, and removes them again when it fails.
// ErrorKind::Io "DIR: cannot create folder (reason)"; "DIR: cannot create folder (P is not a folder)".
void make_output_folders(const std::string& dir);

}  // namespace ibl
