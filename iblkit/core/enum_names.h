// Names of enum values in files and on the command line, from one table per enum:
//
//   inline constexpr EnumName<Window> kWindowNames[] = {{Window::None, "none"}, {Window::Hanning, "hanning"}};
//   name_of(kWindowNames, w)                     → "none"
//   parse_enum(kWindowNames, s, "SH window")     → the value, or ibl::Error listing the valid names
//
// A value may appear more than once: its first entry is its name, the later ones are aliases that
// parse but are not listed.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "iblkit/core/error.h"

namespace ibl {

template <typename E>
struct EnumName {
  E value;
  const char* name;
};

// The first name of v in the table ("?" if v has none).
template <typename E, std::size_t N>
constexpr const char* name_of(const EnumName<E> (&table)[N], E v) {
  for (const auto& e : table)
    if (e.value == v) return e.name;
  return "?";
}

// The value named `name` (its name or an alias), or nullopt.
template <typename E, std::size_t N>
constexpr std::optional<E> find_enum(const EnumName<E> (&table)[N], std::string_view name) {
  for (const auto& e : table)
    if (name == e.name) return e.value;
  return std::nullopt;
}

// Whether table[i] is the first entry of its value (its name, not an alias).
template <typename E, std::size_t N>
constexpr bool is_first_name(const EnumName<E> (&table)[N], std::size_t i) {
  for (std::size_t j = 0; j < i; ++j)
    if (table[j].value == table[i].value) return false;
  return true;
}

// "a, b or c": the first name of each value, aliases left out.
template <typename E, std::size_t N>
std::string enum_names(const EnumName<E> (&table)[N]) {
  std::size_t total = 0;
  for (std::size_t i = 0; i < N; ++i) total += is_first_name(table, i);
  std::string out;
  std::size_t listed = 0;
  for (std::size_t i = 0; i < N; ++i) {
    if (!is_first_name(table, i)) continue;
    if (listed > 0) out += listed + 1 == total ? " or " : ", ";
    out += table[i].name;
    ++listed;
  }
  return out;
}

// The value named `name`; otherwise ErrorKind::Value "[what: ]unknown NOUN 'name' (use a, b or c)".
template <typename E, std::size_t N>
E parse_enum(const EnumName<E> (&table)[N], std::string_view name, std::string_view noun, std::string_view what = {}) {
  if (auto v = find_enum(table, name)) return *v;
  fail(ErrorKind::Value, "{}{}unknown {} '{}' (use {})", what, what.empty() ? "" : ": ", noun, name, enum_names(table));
}

}  // namespace ibl
