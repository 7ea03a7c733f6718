// SH coefficient vectors (RGB per coefficient) and the iblkit.sh/1 JSON format (docs/formats.md):
//   {"format":"iblkit.sh/1","bands":3,"coefficients":[[r,g,b], …]}   (bands² entries, index order)
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "iblkit/core/vec.h"

namespace ibl::sh {

struct Coeffs {
  int bands = 0;
  std::vector<Vec3> c;  // RGB per coefficient, index order k = l(l+1)+m

  Coeffs() = default;
  // bands² zero coefficients.
  explicit Coeffs(int bands_);

  // Σ_k c_k Y_k(d) for unit d.
  Vec3 evaluate(Vec3 d) const;
  // The first `bands` bands (truncating, or padding with zeros).
  Coeffs resized(int new_bands) const;
  // Throws ibl::Error unless bands ∈ [1, kMaxBands], c.size() == bands² and every value is finite.
  void validate(const std::string& what) const;
};

nlohmann::json to_json(const Coeffs& c);
// The file text: one coefficient per line, shortest round-trip decimals.
std::string to_json_text(const Coeffs& c);
// Parses iblkit.sh/1; `what` names the source in error messages.
Coeffs coeffs_from_json(const nlohmann::json& j, const std::string& what);
void write_coeffs(const std::string& path, const Coeffs& c);
Coeffs read_coeffs(const std::string& path);

}  // namespace ibl::sh
