// Reading iblkit's JSON files (manifests, light sets, scenes, paths): one place for the errors a
// user sees when a file is missing, is not JSON, or is another kind of iblkit file.
#pragma once
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"

namespace ibl {

// The parsed file; ErrorKind::Io "PATH: no such file" or "PATH: cannot open" when it cannot be
// read, ErrorKind::Format "PATH: not valid JSON (…)" when it does not parse.
inline nlohmann::json read_json_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(ErrorKind::Io, "{}: no such file", path);
  std::ifstream in(path);
  if (!in) fail(ErrorKind::Io, "{}: cannot open", path);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    fail(ErrorKind::Format, "{}: not valid JSON ({})", path, e.what());
  }
}

// nlohmann's message without its "[json.exception.type_error.302] " tag, for messages that name the
// file and the field themselves: "type must be number, but is string".
inline std::string json_error_text(const nlohmann::json::exception& e) {
  std::string s = e.what();
  if (s.rfind("[json.exception.", 0) == 0) {
    auto k = s.find("] ");
    if (k != std::string::npos) s = s.substr(k + 2);
  }
  return s;
}

// Fails (ErrorKind::Format) unless j is an object whose "format" is `format`, e.g. "iblkit.probes/1".
inline void require_format(const nlohmann::json& j, const std::string& path, const std::string& format) {
  if (!j.is_object() || j.value("format", "") != format)
    fail(ErrorKind::Format, "{}: not an {} file (\"format\" is missing or different)", path, format);
}

}  // namespace ibl
