// The camera's forward model: radiance in the scene -> the code values a camera writes. The lab's
// `lab shoot` photographs through it, and `hdr merge` inverts it (merge.h); its tests measure one
// against the other exactly.
//
// For pixel p and channel c the sensor collects the relative exposure
//   X = L_c(p) · t · (ISO / 100) / N² · wb_c · v(p),   v(p) = 1 − vignetting · r(p)²,
// where t is the exposure time in seconds, N the f-number, r the distance from the image centre
// over the half-diagonal (so 1 s at f/1, ISO 100 turns radiance 1 into X = 1, which saturates).
// Noise (Gaussian approximations, independent per pixel and channel):
//   shot noise: variance X / electrons, electrons = full_well · 100 / ISO (photo-electrons at
//               saturation; 0 turns shot noise off);
//   read noise: standard deviation read_noise (in units of the saturation level), added after.
// Then X is clamped to [0, 1], sent through the response curve and quantised to `bits` bits:
// code = round(response.apply(X) · (2^bits − 1)) / (2^bits − 1).
#pragma once
#include <cstdint>
#include <vector>

#include "iblkit/capture/response.h"
#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/io/dng.h"

namespace ibl::capture {

struct SensorDesc {
  double exposure_s = 1.0;  // exposure time t, seconds
  double f_number = 1.0;    // N
  double iso = 100.0;       // ISO speed
  Vec3 wb_gains{1, 1, 1};   // white-balance gains applied to the linear signal
  double full_well = 0.0;   // photo-electrons at saturation at ISO 100 (0: no shot noise)
  double read_noise = 0.0;  // read noise σ, in units of the saturation level
  double vignetting = 0.0;  // v = 1 − vignetting · r²; in [0, 1)
  Response response = srgb_response();
  int bits = 8;       // 8 or 16
  uint64_t seed = 0;  // noise stream; same seed, same pixels

  // Relative exposure per unit radiance: t · (ISO / 100) / N².
  double exposure_factor() const { return exposure_s * (iso / 100.0) / (f_number * f_number); }
};

// Fails (ibl::Error) unless every field is in range (positive time, f-number, ISO, gains; bits 8 or
// 16; vignetting in [0, 1); noise >= 0; a valid response).
void validate(const SensorDesc& s);

// A raw file's sensor: the black and white levels of its values (a 14-bit sensor by default).
struct RawSensor {
  int black = 512, white = 16383;
  // true: a Bayer mosaic (RGGB), one channel a site, as nearly every camera; false: every channel at every
  // pixel (a LinearRaw DNG, as a three-sensor or Foveon camera, or a raw file already demosaiced).
  bool mosaic = true;
  // The optical low-pass filter in front of a Bayer sensor (a birefringent plate splitting each ray into spots
  // one pixel apart, both ways): the radiance is blurred by [1 2 1] / 4 across and down before the mosaic samples
  // it. Without it a lamp a pixel wide lands on one colour's site and demosaics to any colour (measured: the lab's
  // lamps in a ball came out at 0.2–3 % of their light). Applies to the mosaic only.
  bool olpf = true;
};

// The radiance as an optical low-pass filter passes it: [1 2 1] / 4 across and down, edges clamped.
Image olpf_blur(const Image& radiance);

// What the sensor of a raw file records for `radiance`: the same X and the same noise as expose (the same
// numbers drawn for each pixel and channel) but without the white-balance gains (a raw file records the
// camera's white balance, it does not apply it: write AsShotNeutral = 1 / wb_gains) and without a response
// curve: site value round(black + clamp(X, 0, 1) · (white − black)); with r.mosaic (after r.olpf) one channel a site in
// the RGGB pattern (red at (0, 0), blue at (1, 1)), width × height values; else 3 a pixel (interleaved). Width and
// height must be even. Deterministic given s.seed.
std::vector<uint16_t> expose_raw(const Image& radiance, const SensorDesc& s, const RawSensor& r);

// The raw file of that exposure: expose_raw's mosaic with its levels, AsShotNeutral = 1 / wb_gains, the
// default colour matrix (the lab's channels are linear sRGB's) and the exposure in `meta` (make, model
// given; exposure time, f-number and ISO the sensor's).
io::DngDesc expose_dng(const Image& radiance, const SensorDesc& s, const RawSensor& r, const io::PhotoMeta& meta);

// The code values (in [0, 1], 3 channels; a grey radiance image is repeated) the sensor writes for
// `radiance` (linear RGB, finite and non-negative). Deterministic given s.seed.
Image expose(const Image& radiance, const SensorDesc& s);

}  // namespace ibl::capture
