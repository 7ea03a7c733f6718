// The library's one exception type. The library never exits and never prints to stdout; it throws
// ibl::Error with a message that names the file, the field or the value at fault.
#pragma once
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace ibl {

enum class ErrorKind {
  Io,           // a file is missing, unreadable or unwritable
  Format,       // a file parses but is not what it claims (corrupt, truncated, unknown format)
  Value,        // a value is out of range: NaN/Inf/negative pixel, N = 0, wrong size
  Unsupported,  // a valid request this build cannot serve (optional part not built)
  Internal,     // a bug: an invariant failed
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  ErrorKind kind() const { return kind_; }

 private:
  ErrorKind kind_;
};

template <typename... Args>
[[noreturn]] void fail(ErrorKind kind, fmt::format_string<Args...> f, Args&&... args) {
  throw Error(kind, fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace ibl
