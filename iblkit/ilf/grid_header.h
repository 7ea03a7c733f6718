// The two text lines that open the ILF's binary grid files (.shgrid, .shtree): a magic line and a
// one-line JSON header, read with one-line errors naming the file. Shared by their readers.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "iblkit/core/json_file.h"

#include "iblkit/core/error.h"

namespace ibl::ilf {

// Reads line 1 (must equal magic; else "PATH: not an KIND file …") and parses line 2 as JSON;
// *data_offset is the byte after line 2's newline.
inline nlohmann::json read_grid_header(std::istream& in, const std::string& path, std::string_view magic,
                                       std::string_view kind, size_t* data_offset) {
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

// An integer field's value, checked before it is converted: a JSON integer, or a number with an integral
// value, within [lo, hi] (a float such as 8.9e61 must never reach a cast to an integer type); else
// "PATH: header field "f" = V is not an integer in [lo, hi]". Found by fuzz_shtree (fuzz/crashes/shtree/).
inline int64_t grid_header_integer(const nlohmann::json& v, const std::string& path, const char* f, int64_t lo,
                                   int64_t hi) {
  return json_integer(v, path + ": header", f, lo, hi);
}
inline std::vector<int64_t> grid_header_integers(const nlohmann::json& v, const std::string& path, const char* f,
                                                 int64_t lo, int64_t hi) {
  if (!v.is_array()) fail(ErrorKind::Format, "{}: header field \"{}\" must be an array of integers", path, f);
  std::vector<int64_t> out;
  out.reserve(v.size());
  for (const auto& e : v) out.push_back(grid_header_integer(e, path, f, lo, hi));
  return out;
}

}  // namespace ibl::ilf
