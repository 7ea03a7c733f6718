#include "iblkit/nearfield/ies.h"
#include "iblkit/core/input_file.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "iblkit/core/error.h"
#include "iblkit/nearfield/reconstruct.h"

namespace ibl::nearfield {

namespace {

constexpr double kDeg = kPi / 180;

// Index i and weight f with xs[i] ≤ x ≤ xs[i+1] (clamped), for a sorted table.
void bracket(const std::vector<double>& xs, double x, size_t* i, double* f) {
  if (xs.size() == 1 || x <= xs.front()) {
    *i = 0;
    *f = 0;
    return;
  }
  if (x >= xs.back()) {
    *i = xs.size() - 2;
    *f = 1;
    return;
  }
  size_t k = static_cast<size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin()) - 1;
  *i = k;
  *f = (x - xs[k]) / (xs[k + 1] - xs[k]);
}

}  // namespace

double IesProfile::intensity(Vec3 w) const {
  const double g = std::acos(std::clamp(w.z, -1.0, 1.0)) / kDeg;
  if (g < vertical.front() - 1e-9 || g > vertical.back() + 1e-9) return 0;
  double c = std::atan2(w.y, w.x) / kDeg;
  if (c < 0) c += 360;
  const double hmax = horizontal.back();
  if (horizontal.size() == 1)
    c = 0;
  else if (hmax <= 90 + 1e-9) {
    c = std::fmod(c, 180.0);
    if (c > 90) c = 180 - c;
  }  // quadrant symmetry
  else if (hmax <= 180 + 1e-9) {
    if (c > 180) c = 360 - c;
  }  // bilateral
  const size_t nv = vertical.size();
  size_t iv, ih;
  double fv, fh;
  bracket(vertical, g, &iv, &fv);
  auto row = [&](size_t h) {
    const double a = candela[h * nv + iv], b = nv > 1 ? candela[h * nv + iv + 1] : a;
    return a + (b - a) * fv;
  };
  if (horizontal.size() == 1) return row(0);
  bracket(horizontal, c, &ih, &fh);
  return row(ih) * (1 - fh) + row(ih + 1) * fh;
}

double IesProfile::flux(double max_deg) const {
  double acc = 0;
  const double dg = 0.25 * kDeg, dc = 1.0 * kDeg;
  for (double g = 0.5 * dg; g < std::min(max_deg, 180.0) * kDeg; g += dg)
    for (double c = 0.5 * dc; c < kTwoPi; c += dc)
      acc += intensity({std::sin(g) * std::cos(c), std::sin(g) * std::sin(c), std::cos(g)}) * std::sin(g) * dg * dc;
  return acc;
}

IesProfile parse_ies(const std::string& text, const std::string& what) {
  std::istringstream in(text);
  std::string line;
  bool tilt = false;
  int lines = 0;
  while (std::getline(in, line)) {
    ++lines;
    if (line.rfind("TILT=", 0) == 0 || line.find("TILT=") != std::string::npos) {
      std::string v = line.substr(line.find("TILT=") + 5);
      while (!v.empty() && std::isspace(static_cast<unsigned char>(v.back()))) v.pop_back();
      if (v != "NONE") fail(ErrorKind::Unsupported, "{}: TILT={} is not supported (only TILT=NONE)", what, v);
      tilt = true;
      break;
    }
  }
  if (!tilt) fail(ErrorKind::Format, "{}: not an IES LM-63 file (no TILT= line in {} lines)", what, lines);
  std::vector<double> nums;
  std::string tok;
  while (in >> tok) {
    try {
      size_t used = 0;
      double v = std::stod(tok, &used);
      if (used != tok.size() || !std::isfinite(v)) throw std::invalid_argument(tok);
      nums.push_back(v);
    } catch (const std::exception&) {
      fail(ErrorKind::Format, "{}: '{}' after TILT= is not a number", what, tok);
    }
  }
  if (nums.size() < 13) fail(ErrorKind::Format, "{}: truncated (only {} numbers after TILT=NONE)", what, nums.size());
  IesProfile p;
  p.source = what;
  p.lumens = nums[1];
  const double mult = nums[2];
  // Counts and the type are checked as numbers before they become ints (a cast of 1e30 is undefined).
  if (!(nums[3] >= 1 && nums[4] >= 1 && nums[3] <= 10000 && nums[4] <= 10000))
    fail(ErrorKind::Value,
         "{}: the counts of vertical angles ({}) and horizontal angles ({}) must each lie in 1..10000", what, nums[3],
         nums[4]);
  const int nv = static_cast<int>(nums[3]), nh = static_cast<int>(nums[4]);
  if (std::trunc(nums[5]) != 1)
    fail(ErrorKind::Unsupported, "{}: photometric type {} (only type C = 1)", what, nums[5]);
  p.photometric_type = 1;
  const double ballast = nums[10];
  const size_t need = 13 + static_cast<size_t>(nv) + nh + static_cast<size_t>(nv) * nh;
  if (nums.size() < need)
    fail(ErrorKind::Format, "{}: truncated: {} numbers, {} needed for {}x{} angles", what, nums.size(), need, nv, nh);
  size_t k = 13;
  for (int i = 0; i < nv; ++i) p.vertical.push_back(nums[k++]);
  for (int i = 0; i < nh; ++i) p.horizontal.push_back(nums[k++]);
  for (size_t i = 0; i < static_cast<size_t>(nv) * nh; ++i) {
    const double c = nums[k++] * mult * ballast;
    if (!(c >= 0))
      fail(ErrorKind::Value,
           "{}: candela value {} at index {} (× multiplier {} × ballast {}) is negative or not a number", what,
           nums[k - 1], i, mult, ballast);
    p.candela.push_back(c);
  }
  for (size_t i = 1; i < p.vertical.size(); ++i)
    if (!(p.vertical[i] > p.vertical[i - 1]))
      fail(ErrorKind::Format, "{}: vertical angle {} ({}°) is not greater than the one before it ({}°)", what, i,
           p.vertical[i], p.vertical[i - 1]);
  for (size_t i = 1; i < p.horizontal.size(); ++i)
    if (!(p.horizontal[i] > p.horizontal[i - 1]))
      fail(ErrorKind::Format, "{}: horizontal angle {} ({}°) is not greater than the one before it ({}°)", what, i,
           p.horizontal[i], p.horizontal[i - 1]);
  if (p.vertical.front() < 0 || p.vertical.back() > 180)
    fail(ErrorKind::Value, "{}: vertical angles {}°..{}° lie outside 0..180°", what, p.vertical.front(),
         p.vertical.back());
  return p;
}

IesProfile read_ies(const std::string& path) {
  require_input_file(path, "an IES profile");
  std::ifstream in(path);
  if (!in) fail(ErrorKind::Io, "{}: no such file or not readable", path);
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_ies(ss.str(), path);
}

TexturedSpotlight ies_spotlight(const IesProfile& p, const Placement& placement, double max_deg, int resolution,
                                double scale) {
  if (!(max_deg > 0 && max_deg < 89)) fail(ErrorKind::Value, "IES spotlight: cone {}° must be in (0, 89)", max_deg);
  return far_field_spotlight(
      [&](Vec3 w) {
        return Vec3{1, 1, 1} * (scale * p.intensity(w));
      },
      1.0, std::tan(max_deg * kDeg), resolution, placement);
}

}  // namespace ibl::nearfield
