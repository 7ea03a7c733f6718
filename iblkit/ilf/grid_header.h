// The two text lines that open the ILF's binary grid files (.shgrid, .shtree): a magic line and a
// one-line JSON header, read with one-line errors naming the file. Shared by their readers.
#pragma once
#include <cstddef>
#include <istream>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"

namespace ibl::ilf {

// Reads line 1 (must equal magic; else "PATH: not an KIND file …") and parses line 2 as JSON;
// *data_offset is the byte after line 2's newline.
inline nlohmann::json read_grid_header(std::istream& in, const std::string& path, std::string_view magic, std::string_view kind,
                                       size_t* data_offset) {
  std::string line1, line2;
  std::getline(in, line1);
  if (line1 != magic) fail(ErrorKind::Format, "{}: not an {} file (line 1 is not \"{}\")", path, kind, magic);
  std::getline(in, line2);
  *data_offset = line1.size() + 1 + line2.size() + 1;
  try {
    return nlohmann::json::parse(line2);
  } catch (const nlohmann::json::exception& e) {
    fail(ErrorKind::Format, "{}: header (line 2) does not parse ({})", path, e.what());
  }
}

// Header field f, or "PATH: header field "f" is missing".
inline const nlohmann::json& grid_header_field(const nlohmann::json& h, const std::string& path, const char* f) {
  if (!h.is_object() || !h.contains(f)) fail(ErrorKind::Format, "{}: header field \"{}\" is missing", path, f);
  return h[f];
}

}  // namespace ibl::ilf
