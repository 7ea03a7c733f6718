#include "iblkit/core/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"

namespace ibl {

const char* file_kind_name(unsigned mode) {
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

namespace {
struct stat stat_or_fail(const std::string& path, const char* what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    int e = errno;
    if (e == ENOENT || e == ENOTDIR) fail(ErrorKind::Io, "{}: no such file", path);
    fail(ErrorKind::Io, "{}: cannot read ({})", path, std::strerror(e));
  }
  return st;
}
}  // namespace

void require_input_file(const std::string& path, const char* what) {
  struct stat st = stat_or_fail(path, what);
  if (S_ISDIR(st.st_mode)) fail(ErrorKind::Io, "{}: is a folder, not {}", path, what ? what : "a file");
  if (!S_ISREG(st.st_mode))
    fail(ErrorKind::Io, "{}: is {}, not a regular file (iblkit reads {} from files only)", path,
         file_kind_name(st.st_mode), what ? what : "its inputs");
  note_input_file(path);
}

void require_input_folder(const std::string& path, const char* what) {
  struct stat st = stat_or_fail(path, what);
  if (!S_ISDIR(st.st_mode))
    fail(ErrorKind::Io, "{}: is {}, not a folder{}", path, file_kind_name(st.st_mode),
         what ? fmt::format(" ({})", what) : "");
}

}  // namespace ibl
