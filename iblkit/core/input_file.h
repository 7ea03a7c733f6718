// The one check every reader of a file makes before it opens it (docs/formats.md, "How every input is
// read"): the path names a regular file, after following links. A FIFO, a device (/dev/zero,
// /dev/urandom), a socket or a folder is refused with one line before any codec sees it, so no read
// waits forever or runs without end. While the CLI's OutputTransaction is open, the file is also
// noted as an input of the command, so that no output replaces it (atomic_file.h).
#pragma once
#include <cstdint>
#include <string>

namespace ibl {

// Fails (ErrorKind::Io) unless `path` is a regular file: "PATH: no such file", "PATH: is a folder,
// not a file", "PATH: is a character device, not a regular file (iblkit reads files only)". `what`,
// when given, names what the file is ("image", "probe set") in the message.
void require_input_file(const std::string& path, const char* what = nullptr);

// The same for a folder that is read as a whole (six cube faces, a capture): it must be a folder.
void require_input_folder(const std::string& path, const char* what = nullptr);

// What kind of file system object `mode` (st_mode) is, in words: "a FIFO", "a character device", …
const char* file_kind_name(unsigned mode);

}  // namespace ibl
