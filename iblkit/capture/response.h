// A camera's response curve: per channel, the map between the linear exposure that reached the
// sensor (relative: 1 saturates the sensor) and the code value the camera wrote, in [0, 1].
// Stored as a table of the inverse curve (code value -> relative exposure) at `size` evenly spaced
// code values i / (size - 1), strictly increasing; both directions interpolate it linearly.
// File format iblkit.response/1 (docs/formats.md). Built-in kinds: "linear", "srgb" (IEC 61966-2-1)
// and "camera", a film-like S-curve in log exposure with a toe and a shoulder (docs/capture.md).
#pragma once
#include <array>
#include <string>
#include <vector>

namespace ibl::capture {

struct Response {
  // "linear", "srgb", "camera", "debevec", "robertson", or "file" for a curve read without a kind.
  std::string kind = "srgb";
  // inverse[c][i]: relative exposure of code value i / (size - 1) in channel c (c = 0, 1, 2: R, G, B).
  std::array<std::vector<double>, 3> inverse;

  int size() const { return static_cast<int>(inverse[0].size()); }
  // Code value in [0, 1] for relative exposure x (clamped to [0, inverse(1)]), channel c.
  double apply(double x, int c) const;
  // Relative exposure for code value z in [0, 1] (clamped), channel c.
  double invert(double z, int c) const;

  // Fails (ibl::Error naming `what`) unless every channel has the same size >= 2, finite values,
  // strictly increasing from >= 0.
  void validate(const std::string& what) const;
};

inline constexpr int kBuiltinTableSize = 4096;

Response linear_response(int size = kBuiltinTableSize);
Response srgb_response(int size = kBuiltinTableSize);
// The camera-like curve: z(x) = σ(a·(log2 x − m)) / σ(−a·m), σ the logistic function: a toe below
// m stops under saturation, a shoulder above, z(0) = 0, z(1) = 1. a = contrast per stop, m = the
// curve's midpoint in stops relative to saturation (m < 0).
Response camera_response(double contrast = 0.8, double mid_stops = -2.5, int size = kBuiltinTableSize);
// "linear", "srgb", "camera", or else the path of an iblkit.response/1 file.
Response response_by_name(const std::string& name_or_file);

// Throws ibl::Error (one line naming the photograph and the curve) when a measured curve (kind debevec, robertson or
// file; the analytic linear, srgb and camera tables fit any depth) has fewer code values than a `bits`-bit
// photograph: it was recovered from a shallower camera's codes and says nothing between them.
void check_fits(const Response& r, int bits, const std::string& photo, const std::string& curve);

// iblkit.response/1 (docs/formats.md). read_response throws ibl::Error naming the file.
Response read_response(const std::string& path);
void write_response(const std::string& path, const Response& r);

}  // namespace ibl::capture
