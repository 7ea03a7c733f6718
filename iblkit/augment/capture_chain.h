// From a capture folder to the composite (docs/capture.md, "From the set to the composite"): the chain
// `iblkit composite --capture DIR` runs, each step the one its own command runs:
//   1. hdr merge      each view's bracket into linear HDR; the response curve recovered from view 0's bracket
//                     (Debevec & Malik) unless the folder names one; the backplate is read through the same curve
//                     (the same camera), so that the probe and the photograph differ by exposure and gains only;
//   2. probe from-ball the ball's one or two views unwarped into a probe at the ball's centre, turned into the
//                     world by the direction view 0's camera stood in (registration given by the folder);
//   3. camera solve   the backplate's camera from the board seen in it: the pose, the lens fixed by the folder's
//                     lens file or field of view, else by the backplate's Exif, else one focal length solved;
//   4. composite      the object into the backplate (differential rendering on the proxy), the probe matched to
//                     the photograph (match.h), written back through the curve in the backplate's own format.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "iblkit/augment/run_composite.h"
#include "iblkit/capture/backplate.h"
#include "iblkit/capture/ball.h"
#include "iblkit/capture/bracket.h"
#include "iblkit/capture/camera_solve.h"
#include "iblkit/capture/folder.h"
#include "iblkit/capture/merge.h"

namespace ibl::augment {

struct ChainDesc {
  CompositeJob job;               // sampling, backend, match (the object, material and light come from the folder)
  int probe_size = 128;           // lat-long height of the probe
  int probe_samples = 6;          // n×n looks into the ball photograph per probe texel: a lamp a pixel wide in the
                                  // photograph is averaged into its texel, not hit or missed by 2×2 point samples
  bool exif_lens = true;          // take the backplate's Exif focal length as its lens when the folder gives none
  bool recover_response = false;  // recover the curve from view 0's bracket even when the folder names one
  double max_error_px = 5;        // refuse a board whose reprojection error exceeds this (RMS)
};

struct ChainResult {
  capture::CaptureFolder folder;
  // 1. The brackets.
  std::vector<capture::MergeReport> merges;  // one per view
  capture::Response response;                // the curve used for the ball's brackets and the backplate
  std::string response_source;               // "recovered (Debevec) from view 0", "srgb", a file
  // 2. The probe (world-aligned, RGBA: alpha 0 where no view saw the direction).
  std::vector<capture::BallCircle> circles;  // per view, given or found
  std::vector<double> circle_residual_px;    // per view, the fit's (0: given)
  capture::FromBallResult probe;
  // 3. The camera.
  capture::Solved camera;
  std::string lens_source;  // "the folder's lens file …", "fov_deg …", "Exif …", "focal length solved"
  size_t board_corners = 0;
  // 4. The composite.
  capture::Backplate plate;
  LocalRadiance light;       // the probe as composited: RGB, world-aligned, the match's gains applied
  geometry::TriMesh object;  // the object as inserted (world)
  CompositeRun run;
  Image codes;  // the composite as the backplate's codes (encode_like)
  capture::BackplateReport report;
};

// Throws ibl::Error naming the file and what to do (a board not found, a ball not found, brackets that do not
// merge, a reprojection error above max_error_px).
ChainResult run_capture(const capture::CaptureFolder& folder, const ChainDesc& desc);

}  // namespace ibl::augment
