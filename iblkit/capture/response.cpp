#include "iblkit/capture/response.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "iblkit/core/error.h"
#include "iblkit/core/input_file.h"
#include "iblkit/core/json_file.h"

namespace ibl::capture {

namespace {

constexpr const char* kFormat = "iblkit.response/1";
// Largest table a file may hold: 2^16 + 1 entries covers every 16-bit code value.
constexpr int kMaxTableSize = 65537;

Response tabulate(const char* kind, int size, double (*inv)(double, const double*), const double* p) {
  if (size < 2 || size > kMaxTableSize)
    fail(ErrorKind::Value, "response table size {} outside [2, {}]", size, kMaxTableSize);
  Response r;
  r.kind = kind;
  for (int c = 0; c < 3; ++c) {
    r.inverse[c].resize(size);
    for (int i = 0; i < size; ++i) r.inverse[c][i] = inv(static_cast<double>(i) / (size - 1), p);
  }
  return r;
}

double srgb_inv(double z, const double*) { return z <= 0.04045 ? z / 12.92 : std::pow((z + 0.055) / 1.055, 2.4); }
double linear_inv(double z, const double*) { return z; }
double logistic(double t) { return 1.0 / (1.0 + std::exp(-t)); }
// p[0] = contrast a, p[1] = midpoint m (stops).
double camera_inv(double z, const double* p) {
  if (z <= 0) return 0;
  if (z >= 1) return 1;
  const double s = z * logistic(-p[0] * p[1]);
  return std::exp2(p[1] + std::log(s / (1 - s)) / p[0]);
}

}  // namespace

double Response::invert(double z, int c) const {
  const auto& t = inverse[c];
  const int n = static_cast<int>(t.size());
  const double f = std::clamp(z, 0.0, 1.0) * (n - 1);
  const int i = std::min(static_cast<int>(f), n - 2);
  const double a = f - i;
  return t[i] + a * (t[i + 1] - t[i]);
}

double Response::apply(double x, int c) const {
  const auto& t = inverse[c];
  const int n = static_cast<int>(t.size());
  if (!(x > t.front())) return 0.0;  // NaN too
  if (x >= t.back()) return 1.0;
  // First entry above x: x lies in [t[i-1], t[i]).
  const int i = static_cast<int>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
  const double a = (x - t[i - 1]) / (t[i] - t[i - 1]);
  return (i - 1 + a) / (n - 1);
}

void Response::validate(const std::string& what) const {
  const size_t n = inverse[0].size();
  for (int c = 0; c < 3; ++c) {
    const auto& t = inverse[c];
    if (t.size() != n || n < 2 || n > static_cast<size_t>(kMaxTableSize))
      fail(ErrorKind::Value, "{}: response channel {} has {} entries; every channel needs the same number, 2 to {}",
           what, c, t.size(), kMaxTableSize);
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(t[i]) || t[i] < 0)
        fail(ErrorKind::Value, "{}: response channel {} entry {} = {} is not a finite value >= 0", what, c, i, t[i]);
      if (i > 0 && !(t[i] > t[i - 1]))
        fail(ErrorKind::Value, "{}: response channel {} is not strictly increasing at entry {} ({} after {})", what, c,
             i, t[i], t[i - 1]);
    }
  }
}

Response linear_response(int size) { return tabulate("linear", size, linear_inv, nullptr); }
Response srgb_response(int size) { return tabulate("srgb", size, srgb_inv, nullptr); }
Response camera_response(double contrast, double mid_stops, int size) {
  if (!(contrast > 0.05 && contrast < 20) || !(mid_stops < 0 && mid_stops > -20))
    fail(ErrorKind::Value, "camera response: contrast {} must lie in (0.05, 20) and midpoint {} stops in (-20, 0)",
         contrast, mid_stops);
  const double p[2] = {contrast, mid_stops};
  return tabulate("camera", size, camera_inv, p);
}

Response response_by_name(const std::string& name) {
  if (name == "linear") return linear_response();
  if (name == "srgb") return srgb_response();
  if (name == "camera") return camera_response();
  return read_response(name);
}

Response read_response(const std::string& path) {
  require_input_file(path, "response curve");
  const nlohmann::json j = read_json_file(path);
  require_format(j, path, kFormat);
  Response r;
  r.kind = opt_field(j, path, "kind", "file");
  const auto it = j.find("channels");
  if (it == j.end() || !it->is_array() || it->size() != 3)
    fail(ErrorKind::Format, "{}: field \"channels\" must be an array of three arrays (R, G, B)", path);
  for (int c = 0; c < 3; ++c) {
    const auto& ch = (*it)[c];
    if (!ch.is_array() || ch.size() > static_cast<size_t>(kMaxTableSize))
      fail(ErrorKind::Format, "{}: channels[{}] must be an array of at most {} numbers", path, c, kMaxTableSize);
    r.inverse[c].reserve(ch.size());
    for (const auto& v : ch) {
      if (!v.is_number()) fail(ErrorKind::Format, "{}: channels[{}] holds {}, not a number", path, c, v.dump());
      r.inverse[c].push_back(v.get<double>());
    }
  }
  r.validate(path);
  return r;
}

void write_response(const std::string& path, const Response& r) {
  r.validate(path);
  nlohmann::json ch = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) ch.push_back(r.inverse[c]);
  nlohmann::json j = {{"format", kFormat}, {"kind", r.kind}, {"size", r.size()}, {"channels", ch}};
  write_json_file(path, j, -1);
}

void check_fits(const Response& r, int bits, const std::string& photo, const std::string& curve) {
  if (r.kind == "linear" || r.kind == "srgb" || r.kind == "camera") return;
  const int64_t codes = int64_t(1) << bits;
  if (r.size() >= codes) return;
  fail(ErrorKind::Value,
       "{}: a {}-bit photograph, but the curve {} has {} code values (a {}-bit camera's): recover one from {}-bit "
       "brackets (hdr merge --response-out), or give srgb, linear or camera",
       photo, bits, curve, r.size(), static_cast<int>(std::lround(std::log2(std::max(r.size() - 1, 1)))), bits);
}

}  // namespace ibl::capture
