// Cross-validation of an ILF build: how well the grid predicts a probe it was not built from. The
// probes are dealt into k folds; for each fold the grid built from the other folds is read at the
// fold's probes (trilinearly, as SHGrid::coeffs_at reads a grid) and its SH compared with the probes'
// own SH through the same basis rows (the same buckets, the same solid angles). One pass: every fold
// is splatted into a raster of its own, so that "all but fold f" is a difference of sums (CvBucket).
// The same machinery chooses the kernel width and the grid resolution (`--kernel auto`, `--grid auto`).
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/ilf/buckets.h"
#include "iblkit/ilf/project.h"
#include "iblkit/ilf/shgrid.h"

namespace ibl::ilf {

struct CrossValDesc {
  int folds = 5;             // k ≥ 2; 0: no cross-validation
  uint64_t seed = 1;         // fold assignment and evaluated subset
  int max_evaluated = 8192;  // at most this many held-out probes are predicted (a random subset beyond)
  int regions = 2;           // per axis: the volume's regions for per-region errors (2 = octants)
};

struct CrossValResult {
  int folds = 0;
  int evaluated = 0;                 // probes predicted
  double rel_error = 0;              // √(Σ_p ‖Ĉ_p − C_p‖² / Σ_p ‖C_p‖²) over the evaluated probes
  double median_probe_error = 0;     // median over probes of ‖Ĉ_p − C_p‖ / ‖C_p‖
  int regions = 0;                   // per axis
  std::vector<double> region_error;  // regions³, x fastest; NaN where no probe fell
  std::vector<int> region_probes;
  std::vector<Vec3> positions;            // evaluated probes
  std::vector<double> sq_error, sq_norm;  // per evaluated probe: ‖Ĉ_p − C_p‖², ‖C_p‖²
};

// Deals n probes into k folds (a seeded random permutation, round robin).
std::vector<uint8_t> assign_folds(int n, int folds, uint64_t seed);

// Accumulates the cross-validation over a build's loop of bucket blocks.
class CrossValidator {
 public:
  CrossValidator(const GridDesc& grid, const std::vector<Vec3>& origins, const std::vector<uint8_t>& valid, int bands,
                 const CrossValDesc& desc);
  void begin_block(int D);                // D buckets in the coming block
  CvBucket bucket(int j);                 // column j of the block (thread-safe for distinct j)
  void end_block(const float* B, int D);  // B: the block's basis rows (D × K, column-major, as bucket_basis)
  CrossValResult result() const;
  // The sums so far (Σ over blocks of the predictions' and the probes' own SH products), as
  // 2·3·E·K doubles. They are additive over blocks: a distributed job sums every process's
  // (CvShare::sum) before result().
  std::vector<double>& partial_sums() { return C_; }

 private:
  GridDesc grid_;
  CrossValDesc desc_;
  int K_ = 0, E_ = 0;  // coefficients, evaluated probes
  std::vector<uint8_t> fold_;
  std::vector<int32_t> cell_;
  std::vector<float> frac_;
  std::vector<int> eval_;  // evaluated probe ids
  std::vector<Vec3> pos_;
  std::vector<float> pred_, own_;
  std::vector<double> C_;  // Cpred then Cown (3·E × K each): accumulate_block sums over blocks in double
};

// A process's share of a cross-validation split between the processes of a job (ilf/mpi/, docs/ilf.md
// "On a cluster"): it evaluates the sampled buckets of blocks [block_begin, block_end) only — the
// buckets are sampled by their global index, so the job evaluates the serial build's buckets — and the
// partial sums meet through `sum`. One process (the default) has every block and no hooks.
struct CvShare {
  int block_begin = 0, block_end = std::numeric_limits<int>::max();
  // Runs f (local work, no collective calls) and lets every process learn whether it failed on any:
  // then all of them throw the same error. Empty: f().
  std::function<void(const std::function<void()>& f)> agree;
  // Replaces n doubles by their sum over the job's processes, the same bits on every process (so that
  // every process makes the same choice). Empty: nothing to add.
  std::function<void(double* data, size_t n)> sum;
};

// The error volume beside a grid (`ilf build --error-grid`): at each of its points (the build grid's
// resolution, at most max_res per axis) the cross-validated error of the probes around it, weighted
// by a Gaussian of σ = max(the mean probe spacing (V/P)^⅓, the volume's spacing): channel 0 the
// relative error √(Σw·e²/Σw·‖C‖²), channel 1 the absolute RMS SH error √(Σw·e²/Σw), channel 2 the
// weight Σw (≈ probes within σ). Stored as a one-band .shgrid of content "cv-error".
SHGrid error_volume(const CrossValResult& r, const GridDesc& grid, int max_res = 32);

// An error volume on the axis-aligned plane `axis` = value (0 x, 1 y, 2 z): its three channels,
// trilinearly interpolated, `width` pixels along the plane's first axis (image x: z for x-planes, else
// x; image y: down the other axis), as `ilf slice` lays out irradiance.
Image error_slice(const SHGrid& ev, int axis, double value, int width);
// Channel 0 (the relative error) in false colour, linear RGB in [0, 1]: 0 black, then blue, green,
// yellow, and red at max_error and above; grey where the weight (channel 2, ≈ probes within σ) is
// below kErrorMinWeight — no probe near enough to give a figure (a gap in the capture, which would
// otherwise read as 0, black).
inline constexpr double kErrorMinWeight = 1.0;
Image error_colours(const Image& slice, double max_error);

// Where the grid will be read — an object to be lit (`ilf build --focus`, augment/): the automatic
// choice then minimises the cross-validated error of the probes around it rather than the whole
// volume's, each probe weighted by a Gaussian of σ = max(radius, the mean probe spacing (V/P)^⅓ of the
// P evaluated probes in the volume V) around the centre, cut at 3σ (the same σ for every candidate, so
// that resolutions compare).
struct Focus {
  Vec3 centre;
  double radius = 0;  // the object's radius (m); 0: a point
};
// The focus's σ for a cross-validation of `probes` evaluated probes over `volume`.
double focus_sigma(const Focus& f, const Box& volume, int probes);
// √(Σw·e²/Σw·‖C‖²) over the evaluated probes, w the focus's weights; *weight: Σw (≈ probes within σ).
// NaN when no probe lies within 3σ.
double focus_error(const CrossValResult& r, const Focus& f, const Box& volume, double* weight = nullptr);

// The automatic choice of kernel width and resolution: cross-validated error of each candidate on a
// subset of the buckets (every s-th, at most max_buckets), the least wins (with a focus: the least
// focus_error).
struct ResampleTrial {
  int n = 0;
  double kernel = 0;
  double cv_error = 0;     // over the whole volume
  double focus_error = 0;  // around the focus (NaN without one)
};
struct ResampleChoice {
  int nx = 0, ny = 0, nz = 0;
  double kernel = 0;
  std::vector<ResampleTrial> trials;
  size_t chosen = 0;    // the chosen trial (index into trials)
  CrossValResult best;  // the chosen candidate's cross-validation
  int buckets_used = 0;
  double seconds = 0;
  std::optional<Focus> focus;  // the choice was made for this neighbourhood
  double focus_weight = 0;     // Σw of the chosen trial (≈ probes within σ)
  double focus_sigma = 0;      // σ of its weights (m)
  double volume_kernel = 0;    // the whole volume's best trial (with a focus: what it would have chosen
  int volume_n = 0;            // among the trials run)
};
inline constexpr double kAutoKernels[] = {1.5, 2.0, 2.5, 3.0, 4.0};
inline constexpr int kAutoGrids[] = {8, 12, 16, 24, 32, 48, 64};

struct ResampleSearch {
  bool kernel = false, grid = false;  // what to choose
  Box volume;
  int nx = 16, ny = 16, nz = 16;  // the resolution when not chosen (or the aspect when chosen: the
                                  // chosen n is the longest axis)
  double kernel_cells = 3;        // the kernel when not chosen
  int bands = 5;
  size_t memory_bytes = size_t(2) << 30;  // grids whose build needs more are not tried
  int max_buckets = 2048;
  std::optional<Focus> focus;  // choose for this neighbourhood (focus_error) instead of the whole volume
};

// Bytes a build of this resolution holds (grid, SH accumulator, one block of bucket columns).
double build_grid_bytes(int nx, int ny, int nz, int bands, int block_buckets);

// Distributed: every process calls it with the same arguments and its own share; every process gets the
// job's choice.
ResampleChoice choose_resampling(const BucketStore& store, const std::vector<Vec3>& origins, const ProjectDesc& project,
                                 const ResampleSearch& search, const CrossValDesc& cv, bool use_starts,
                                 const CvShare& share = {});

// The cross-validation of one build (grid, kernel) on every s-th bucket, at most max_buckets of them
// (all when there are fewer): one read of the block files. buckets_used: the job's count. Distributed
// as choose_resampling: every process gets the job's result.
CrossValResult cross_validate(const BucketStore& store, const std::vector<Vec3>& origins, const GridDesc& grid,
                              const ProjectDesc& project, int bands, const CrossValDesc& cv, int max_buckets,
                              bool use_starts, int* buckets_used = nullptr, const CvShare& share = {});

// The rays of bucket b of block k (loaded into buf); their radiance is converted into `rad`, which
// the returned rays point into.
struct BucketRadiance {
  std::vector<float> rgb;
  int64_t stride = 0;
};
BucketRays bucket_rays(const BucketStore& store, const std::vector<uint16_t>& buf, int k, int b,
                       const std::vector<Vec3>& origins, bool use_starts, BucketRadiance& rad);

}  // namespace ibl::ilf
