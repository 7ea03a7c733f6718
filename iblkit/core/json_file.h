// Reading and writing iblkit's JSON files (manifests, light sets, scenes, paths): one place for the
// errors a user sees when a file is missing, is not JSON, or is another kind of iblkit file, and one
// writer that reports failure and replaces the file whole (core/atomic_file.h).
#pragma once
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/input_file.h"
#include "iblkit/core/vec.h"

namespace ibl {

// The parsed file; ErrorKind::Io "PATH: no such file" or "PATH: cannot open" when it cannot be
// read, ErrorKind::Format "PATH: not valid JSON (…)" when it does not parse.
inline nlohmann::json read_json_file(const std::string& path) {
  require_input_file(path);  // a FIFO or a device is refused before it is read (input_file.h)
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

// A JSON number as an integer, checked before anything narrows it (the one rule for every integer
// of every iblkit file): a JSON integer, or a number with an integral value, within [lo, hi]; else
// ErrorKind::Format "WHERE: field "f" = V is not a whole number in [lo, hi]". (nlohmann's get<int>
// reads 4294967360 as 64.)
inline int64_t json_integer(const nlohmann::json& v, const std::string& where, const char* field, int64_t lo,
                            int64_t hi) {
  if (v.is_number_unsigned()) {
    const uint64_t u = v.get<uint64_t>();
    if (hi >= 0 && u <= static_cast<uint64_t>(hi) && static_cast<int64_t>(u) >= lo) return static_cast<int64_t>(u);
  } else if (v.is_number_integer()) {
    const int64_t i = v.get<int64_t>();
    if (i >= lo && i <= hi) return i;
  } else if (v.is_number_float()) {
    const double d = v.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && d >= static_cast<double>(lo) && d <= static_cast<double>(hi))
      return static_cast<int64_t>(d);
  }
  fail(ErrorKind::Format, "{}: field \"{}\" = {} is not a whole number in [{}, {}]", where, field, v.dump(), lo, hi);
}
// The same for integer type T's whole range.
template <typename T>
T json_integer(const nlohmann::json& v, const std::string& where, const char* field) {
  static_assert(std::is_integral_v<T> && sizeof(T) <= 8);
  constexpr int64_t hi = sizeof(T) == 8 && std::is_unsigned_v<T> ? std::numeric_limits<int64_t>::max()
                                                                 : static_cast<int64_t>(std::numeric_limits<T>::max());
  return static_cast<T>(json_integer(v, where, field, static_cast<int64_t>(std::numeric_limits<T>::min()), hi));
}

namespace detail {
template <typename T>
constexpr const char* json_kind() {
  if constexpr (std::is_same_v<T, bool>)
    return "true or false";
  else if constexpr (std::is_same_v<T, std::string>)
    return "a string";
  else if constexpr (std::is_integral_v<T>)
    return "a whole number";
  else
    return "a number";
}
template <typename T>
bool json_is(const nlohmann::json& v) {
  if constexpr (std::is_same_v<T, bool>)
    return v.is_boolean();
  else if constexpr (std::is_same_v<T, std::string>)
    return v.is_string();
  else if constexpr (std::is_integral_v<T>)
    return v.is_number_integer();
  else
    return v.is_number();
}
}  // namespace detail

// Field `key` of the object j as T (bool, a whole number, double, std::string); `def` when j has no
// such field. ErrorKind::Format "WHERE: field \"key\" must be a number, got \"x\"" when it has another
// type, and "WHERE: expected a JSON object" when j is not one (WHERE: the file, or "file: probes[2]").
template <typename T>
T opt_field(const nlohmann::json& j, const std::string& where, const char* key, T def) {
  if (!j.is_object()) fail(ErrorKind::Format, "{}: expected a JSON object, got {}", where, j.type_name());
  auto it = j.find(key);
  if (it == j.end()) return def;
  if (!detail::json_is<T>(*it))
    fail(ErrorKind::Format, "{}: field \"{}\" must be {}, got {}", where, key, detail::json_kind<T>(), it->dump());
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>)
    return json_integer<T>(*it, where, key);  // range-checked before narrowing
  else
    return it->template get<T>();
}
inline std::string opt_field(const nlohmann::json& j, const std::string& where, const char* key, const char* def) {
  return opt_field<std::string>(j, where, key, std::string(def));
}
// The same for a field that must be present: "WHERE: field \"key\" is missing".
template <typename T>
T req_field(const nlohmann::json& j, const std::string& where, const char* key) {
  if (j.is_object() && !j.contains(key)) fail(ErrorKind::Format, "{}: field \"{}\" is missing", where, key);
  return opt_field<T>(j, where, key, T{});
}

// Field `key` of the object j as a finite [x, y, z]: "WHERE: field \"key\" is missing" / "must be [x, y, z] (finite
// numbers), got …" (ErrorKind::Format).
inline Vec3 json_vec3(const nlohmann::json& j, const std::string& where, const char* key) {
  if (!j.is_object() || !j.contains(key)) fail(ErrorKind::Format, "{}: field \"{}\" is missing", where, key);
  const auto& a = j[key];
  if (a.is_array() && a.size() == 3 && a[0].is_number() && a[1].is_number() && a[2].is_number()) {
    Vec3 v{a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
    if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) return v;
  }
  fail(ErrorKind::Format, "{}: field \"{}\" must be [x, y, z] (finite numbers), got {}", where, key, a.dump());
}

// Fails (ErrorKind::Format) unless j is an object whose "format" is `format`, e.g. "iblkit.probes/1".
inline void require_format(const nlohmann::json& j, const std::string& path, const std::string& format) {
  if (!j.is_object() || !j.contains("format") || j["format"] != format)
    fail(ErrorKind::Format, "{}: not an {} file (\"format\" is missing or different)", path, format);
}

// Writes j.dump(indent) and a newline to path through a temporary file renamed into place;
// ErrorKind::Io "PATH: cannot write (reason)" on failure, the previous file at path then intact.
inline void write_json_file(const std::string& path, const nlohmann::json& j, int indent = 1) {
  write_file_atomically(path, j.dump(indent) + "\n");
}

}  // namespace ibl
