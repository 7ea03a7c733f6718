// One entry point for every extraction method (median cut, its 2^K form, variance cut, irradiance
// optimisation), and the evaluation of methods × light counts against a probe's exact ground-truth
// irradiance with a spherical-harmonic reference line (Madsen & Laursen 2007 §5, Fig. 4).
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/lights/optimize.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lights {

// The names of the extraction methods, in the order they are listed to a user.
const std::vector<std::string>& extraction_methods();
// "median-cut, median-cut-2k, variance-cut, optimize".
std::string extraction_method_list();
// Throws ibl::Error (Value) naming the method and the known ones unless `method` is one of them.
void check_method(const std::string& method);

struct ExtractDesc {
  std::string method = "median-cut";  // one of extraction_methods()
  int count = 16;                     // number of lights N ≥ 1 (median-cut-2k: a power of two)
  double min_separation_deg = 0;      // merge lights closer than this many degrees, then cut further (0: off)
  // "optimize": the optimiser's settings and the icosphere level of its normals (count and
  // min_separation_deg are taken from above; init picks the starting cut).
  OptimizeDesc optimize;
  ProgressFn progress;  // optional: ground truth and optimiser progress ("optimize" only)
};

struct Extraction {
  LightSet set;
  double seconds = 0;        // wall time of the extraction (the optimiser's ground truth excluded)
  int normals = 0;           // "optimize": the M normals the lights were fitted at (0 otherwise)
  OptimizeReport optimizer;  // filled for "optimize"
};

// One method at one count. For "optimize", `normals` and `ground_truth` are the optimiser's targets
// (pass them to share them between several counts); when both are empty they are computed here, at
// the icosphere face centres of level desc.optimize.normals_level. Throws ibl::Error for an unknown
// method, a level outside [kMinNormalsLevel, kMaxNormalsLevel] or a probe the method cannot serve.
Extraction extract(const sphere::EnvMap& env, const ExtractDesc& desc, const std::vector<Vec3>& normals = {},
                   const std::vector<Vec3>& ground_truth = {});

// ---- methods × counts ---------------------------------------------------------------------------

struct MethodsEvalDesc {
  std::vector<std::string> methods = {"median-cut", "variance-cut", "optimize"};  // extraction methods
  std::vector<int> counts = {1,  2,  4,   8,  16,
                             32, 64, 128, 256};  // light counts N (median-cut-2k skips non-powers of two)
  int normals_level = 5;                         // icosphere level of the M normals (5: 20480, as the paper)
  int sh_bands = 3;                              // bands of the SH reference line (≤ 0: none; at most sh::kMaxBands)
  double min_separation_deg = 0;                 // minimum angular separation of the lights in degrees (0: off)
  int picture_count = 16;         // the N whose light sets are kept for pictures (EvalResult::picture_sets)
  OptimizeDesc optimize;          // "optimize": iterations, tolerance, initial cut (count is each N)
  std::optional<LightSet> given;  // also evaluated, as the row "<method> (file)" (a set read from a file)
  ProgressFn progress;            // optional: stages "ground truth" and "eval" (per method and count)
};

struct EvalRow {
  std::string method;                       // extraction method, or "<method> (file)" for the given set
  int count = 0;                            // lights in the set
  ErrorStats err;                           // against the ground truth
  double seconds = 0;                       // extraction time (0 for the given set)
  std::optional<OptimizeReport> optimizer;  // "optimize" rows
};

struct EvalResult {
  std::vector<EvalRow> rows;                     // given set first, then methods × counts in order
  int normals = 0;                               // M
  int sh_bands = 0;                              // bands of the SH reference (0: none)
  bool have_sh = false;                          // sh holds the SH reference's errors
  ErrorStats sh;                                 // SH irradiance against the ground truth
  double ground_truth_seconds = 0;               // time of the ground truth
  std::map<std::string, LightSet> picture_sets;  // per method, its set at picture_count lights (and the given set)
};

// Ground truth at the normals, the SH reference, then every method at every count. Throws ibl::Error
// for an unknown method, a level outside [kMinNormalsLevel, kMaxNormalsLevel], SH bands above
// sh::kMaxBands or a count the probe cannot serve.
EvalResult evaluate_methods(const sphere::EnvMap& env, const MethodsEvalDesc& desc);

// The name of the SH reference row: "sh-<bands>band" (e.g. "sh-3band").
std::string sh_reference_name(int bands);

// The result as CSV: a header, one row per EvalRow, then the SH reference row (sh_reference_name,
// bands² coefficients as its count). Columns: method, count, mean_rel, max_rel, rms_rel, rms_abs,
// mean_irradiance_Y, seconds, iterations, final_iterations, converged, initial_cost, final_cost.
void write_eval_csv(const std::string& path, const EvalResult& result);

}  // namespace ibl::lights
