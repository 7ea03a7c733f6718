#include "iblkit/sh/coeffs.h"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/sh/basis.h"

namespace ibl::sh {

Coeffs::Coeffs(int bands_) : bands(bands_) {
  if (bands_ < 1 || bands_ > kMaxBands) fail(ErrorKind::Value, "SH bands must be in 1..{} (got {})", kMaxBands, bands_);
  c.assign(coeff_count(bands_), Vec3{});
}

Vec3 Coeffs::evaluate(Vec3 d) const {
  if (bands <= 0) return {};
  double y[kMaxBands * kMaxBands];
  eval_basis(bands, d, y);
  Vec3 s;
  for (int k = 0; k < coeff_count(bands); ++k) s += c[k] * y[k];
  return s;
}

Coeffs Coeffs::resized(int new_bands) const {
  Coeffs out(new_bands);
  for (int k = 0; k < std::min(coeff_count(new_bands), static_cast<int>(c.size())); ++k) out.c[k] = c[k];
  return out;
}

void Coeffs::validate(const std::string& what) const {
  if (bands < 1 || bands > kMaxBands)
    fail(ErrorKind::Value, "{}: SH bands must be in 1..{} (got {})", what, kMaxBands, bands);
  if (static_cast<int>(c.size()) != coeff_count(bands))
    fail(ErrorKind::Value, "{}: {} bands need {} coefficients, got {}", what, bands, coeff_count(bands), c.size());
  for (size_t k = 0; k < c.size(); ++k)
    for (int ch = 0; ch < 3; ++ch)
      if (!std::isfinite(c[k][ch])) fail(ErrorKind::Value, "{}: coefficient {} channel {} is not finite", what, k, ch);
}

nlohmann::json to_json(const Coeffs& c) {
  nlohmann::json arr = nlohmann::json::array();
  for (const Vec3& v : c.c) arr.push_back({v.x, v.y, v.z});
  return {{"format", "iblkit.sh/1"}, {"bands", c.bands}, {"coefficients", arr}};
}

std::string to_json_text(const Coeffs& c) {
  std::string s = fmt::format("{{\n  \"format\": \"iblkit.sh/1\",\n  \"bands\": {},\n  \"coefficients\": [\n", c.bands);
  for (size_t k = 0; k < c.c.size(); ++k)
    s += fmt::format("    [{}, {}, {}]{}\n", c.c[k].x, c.c[k].y, c.c[k].z, k + 1 < c.c.size() ? "," : "");
  return s + "  ]\n}\n";
}

Coeffs coeffs_from_json(const nlohmann::json& j, const std::string& what) {
  if (!j.is_object()) fail(ErrorKind::Format, "{}: expected a JSON object", what);
  if (!j.contains("format") || j["format"] != "iblkit.sh/1")
    fail(ErrorKind::Format, "{}: \"format\" must be \"iblkit.sh/1\"", what);
  if (!j.contains("bands") || !j["bands"].is_number_integer())
    fail(ErrorKind::Format, "{}: \"bands\" must be an integer", what);
  int bands = json_integer<int>(j["bands"], what, "bands");  // 2^32 + 3 is refused, not read as 3
  if (bands < 1 || bands > kMaxBands)
    fail(ErrorKind::Value, "{}: \"bands\" must be in 1..{} (got {})", what, kMaxBands, bands);
  if (!j.contains("coefficients") || !j["coefficients"].is_array())
    fail(ErrorKind::Format, "{}: \"coefficients\" must be an array", what);
  const auto& arr = j["coefficients"];
  if (static_cast<int>(arr.size()) != coeff_count(bands))
    fail(ErrorKind::Value, "{}: {} bands need {} coefficients, got {}", what, bands, coeff_count(bands), arr.size());
  Coeffs c(bands);
  for (size_t k = 0; k < arr.size(); ++k) {
    const auto& e = arr[k];
    if (!e.is_array() || e.size() != 3) fail(ErrorKind::Format, "{}: coefficient {} must be [r,g,b]", what, k);
    for (int ch = 0; ch < 3; ++ch) {
      if (!e[ch].is_number()) fail(ErrorKind::Format, "{}: coefficient {} channel {} is not a number", what, k, ch);
      c.c[k][ch] = e[ch].get<double>();
    }
  }
  c.validate(what);
  return c;
}

void write_coeffs(const std::string& path, const Coeffs& c) {
  c.validate(path);
  write_file_atomically(path, to_json_text(c));
}

Coeffs read_coeffs(const std::string& path) { return coeffs_from_json(read_json_file(path), path); }

}  // namespace ibl::sh
