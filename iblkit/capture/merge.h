// HDR assembly from a bracket of photographs (issue 29 §1, docs/capture.md "HDR merge"):
// response recovery (Debevec & Malik 1997 [1], Robertson, Borman & Stevenson 2003 [2]),
// translation alignment (Ward 2003 [3]), the weighted merge, its absolute scale and its report.
//
// [1] P. Debevec, J. Malik, "Recovering high dynamic range radiance maps from photographs",
//     SIGGRAPH 1997.
// [2] M. Robertson, S. Borman, R. Stevenson, "Estimation-theoretic approach to dynamic range
//     enhancement using multiple exposures", J. Electronic Imaging 12(2), 2003.
// [3] G. Ward, "Fast, robust image registration for compositing high dynamic range photographs
//     from hand-held exposures", J. Graphics Tools 8(2), 2003.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "iblkit/capture/response.h"
#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"

namespace ibl::capture {

// One photograph of the bracket: code values in [0, 1] (3 channels) and its relative exposure
// Δ = t · (ISO / 100) / N² (1 s at f/1, ISO 100 is 1).
struct Frame {
  Image codes;
  double exposure = 1.0;
  std::string name;  // for messages: the file
};

// Code values the merge and the recovery trust: the hat weight (docs/capture.md) is 0 at or below
// kBlackCode and at or above kSaturatedCode, 1 at 0.5, linear in between.
inline constexpr double kBlackCode = 0.02;
inline constexpr double kSaturatedCode = 0.98;
double hat_weight(double z);

struct RecoverDesc {
  int bins = 256;         // table size of the recovered curve
  int samples = 16384;    // pixels sampled for Debevec: one per cell of a 128 × 128 grid
  double smoothness = 5;  // κ: λ² = κ · (data rows per bin); 5 chosen on held-out probes (docs/capture.md)
};
// Debevec & Malik: least squares for g = ln(inverse) with a second-difference smoothness term.
Response recover_debevec(const std::vector<Frame>& frames, const RecoverDesc& desc = {});
// Robertson et al.: alternating estimates of the radiance and the curve, Gaussian noise model.
Response recover_robertson(const std::vector<Frame>& frames, const RecoverDesc& desc = {});

// Ward's median threshold bitmaps: the integer shift (dx, dy) of each frame relative to the
// reference frame (frame `reference` gets (0, 0)), so that frame pixel (x + dx, y + dy) shows what
// reference pixel (x, y) shows. Searches |shift| < 2^levels.
std::vector<std::array<int, 2>> align_mtb(const std::vector<Frame>& frames, int reference, int levels = 6);

struct MergeDesc {
  std::optional<Response> response;  // known curve; else recovered with `method`
  std::string method = "debevec";    // "debevec" or "robertson"
  RecoverDesc recover;
  bool align = true;
  int align_levels = 6;
  double scale = 1.0;  // multiplies the result (after the grey card's scale, if any)
  // Grey card: rectangle x, y, w, h in pixels (of the reference frame) and its reflectance. The
  // result is scaled and white-balanced so that the card's mean reads `reflectance` in every channel.
  std::optional<std::array<int, 4>> grey_card;
  double reflectance = 0.18;
};

struct MergeReport {
  Response response;                       // the curve used (given or recovered)
  std::vector<std::array<int, 2>> shifts;  // per frame
  int reference = 0;                       // the frame the others are aligned to
  int64_t pixels = 0;
  int64_t saturated_everywhere = 0;  // pixels with a channel at or above kSaturatedCode in every frame
  int64_t black_everywhere = 0;      // pixels with a channel at or below kBlackCode in every frame
  int64_t well_exposed = 0;          // pixels with every channel trusted (weight > 0) in some frame
  double dynamic_range_stops = 0;    // log2(max / min) of trusted luminance (0.1 / 99.9 percentiles)
  double min_luminance = 0, max_luminance = 0;
  double noise = 0;     // median relative deviation of one frame's radiance from the merge (docs/capture.md)
  Vec3 gains{1, 1, 1};  // the grey card's per-channel factors times `scale`
};

// Checks the bracket (sizes, count, exposure spread, all saturated), aligns, recovers the curve when
// none is given, merges, scales. Throws ibl::Error naming the frame and what to do.
Image merge_hdr(const std::vector<Frame>& frames, const MergeDesc& desc, MergeReport* report = nullptr);

}  // namespace ibl::capture
