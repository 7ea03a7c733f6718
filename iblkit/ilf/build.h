// `ilf build`: probe sequence → SH grid, the pipeline of [1] §3 as batched kernels over blocks of
// direction buckets: (1) optional sub-sampling, (2) out-of-core bucket sort, then per block
// (3) radiance projection of every bucket onto the grid, (4) repair, (5) SH accumulation as one matrix
// product (grid points × buckets)·(buckets × coefficients). A GPU backend or a distributed driver
// replaces the per-block loop (project_block / accumulate_block) without touching the maths.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <optional>
#include <string>

#include "iblkit/core/progress.h"
#include "iblkit/ilf/buckets.h"
#include "iblkit/ilf/collective.h"
#include "iblkit/ilf/crossval.h"
#include "iblkit/ilf/project.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/ilf/subsample.h"

namespace ibl::ilf {

// The SH bands a build accepts (BuildDesc::bands).
inline constexpr int kMinBuildBands = 1, kMaxBuildBands = 10;

struct BuildDesc {
  int nx = 16, ny = 16, nz = 16;           // grid resolution (points per axis)
  std::optional<Box> volume;               // grid volume; default the sequence's volume
  int bands = 5;                           // SH bands (5 = 25 coefficients), in [kMinBuildBands, kMaxBuildBands]
  ProjectDesc project;                     // kernel, raster, repair
  BucketDesc buckets{.octahedral = -1};    // bucket folder, memory budget, skip-bad; octahedral −1: auto (below)
  int auto_pixel_buckets = 1 << 20;        // auto: one bucket per pixel when a frame has at most this many pixels
  int auto_octahedral = 256;               // auto: otherwise n×n octahedral buckets with this n
  std::optional<SubsampleDesc> subsample;  // sub-sample first when set
  bool auto_kernel = false;                // choose project.kernel_cells by cross-validation (kAutoKernels)
  bool auto_grid = false;                  // choose the resolution by cross-validation (kAutoGrids; nx, ny, nz
                                           // give the aspect; builds over half of buckets.memory_bytes not tried)
  CrossValDesc crossval{.folds = 0};       // folds ≥ 2: report the cross-validated error (BuildReport::crossval)
  int auto_max_buckets = 2048;             // cross-validation and the automatic choice use at most this many
                                           // buckets (every s-th; all when there are fewer)
  std::optional<Focus> focus;              // make the automatic choice for this neighbourhood (crossval.h):
                                           // where an object will be lit; needs auto_kernel or auto_grid
  bool ball_parallax = true;               // start each ray at its reflection point on the ball (Sequence::ball);
                                           // false: every ray through the probe position (single viewpoint)
};

struct BuildReport {
  int probes_in = 0, probes_used = 0;  // before and after sub-sampling / skipping
  int skipped = 0;                     // probes skipped as bad (--skip-bad)
  int subsampled_out = 0;              // probes dropped by sub-sampling
  std::vector<std::string> skip_reasons;
  int buckets = 0, blocks = 0;    // direction buckets and blocks
  int octahedral = 0;             // 0 = pixel buckets
  int64_t samples = 0;            // radiance samples (rays) used
  int64_t uncovered = 0;          // (grid point, bucket) pairs filled by the repair
  double fraction_uncovered = 0;  // uncovered / (grid points · buckets)
  bool buckets_reused = false;    // an earlier run's bucket files were reused
  double t_read = 0;              // decoding the frames (part of t_sort)
  double t_subsample = 0, t_sort = 0, t_project = 0, t_accumulate = 0, t_total = 0;  // seconds
  double t_repair = 0;                     // the repair's share of t_project (its share of the buckets' thread time)
  double gemm_flops = 0;                   // floating-point operations of the SH matrix products
  int nx = 0, ny = 0, nz = 0;              // the resolution built (chosen with auto_grid)
  double kernel_cells = 0;                 // the kernel used (chosen with auto_kernel)
  double ball_radius = 0;                  // rays started on a ball of this radius (0: single viewpoint)
  std::optional<ResampleChoice> choice;    // the automatic choice, when made
  std::optional<CrossValResult> crossval;  // the cross-validated error, when asked for
  int crossval_buckets = 0;                // buckets the cross-validation used
  double t_choose = 0, t_crossval = 0;     // seconds of the automatic choice, of a separate cross-validation
                                           // (fixed kernel and grid); both part of t_total
};

// SH accumulation of one block: C (rows × K, column-major) += R (rows × D, column-major) · B (D × K,
// column-major), in parallel over row chunks (Eigen for the products). The product is taken in float,
// the sum over blocks in double (so that it does not depend on the blocks' order). Returns the flop count.
double accumulate_block(const float* R, int64_t rows, int D, const float* B, int K, double* C);

// Basis rows of buckets [b0, b1): B(j, k) = Σ_{q ∈ bucket b0+j} Ω_q·Y_k(ω_q), column-major (D × K).
std::vector<float> bucket_basis(const DirectionTable& t, int b0, int b1, int bands);

// The build. Split between the processes of a job by `team` (collective.h; none: this process
// alone): every process calls it with the same arguments, process 0 returns the grid and the others
// an empty one; `report`'s counts are the job's, its seconds this process's; give `progress` on
// process 0 (it follows the whole job).
SHGrid build_shgrid(const Sequence& seq, const BuildDesc& desc, const ProgressFn& progress = {},
                    BuildReport* report = nullptr, Collective* team = nullptr);
// What the processes of a split build must agree on (Collective::agree_on): every setting of desc and
// a fingerprint of the sequence (manifest, frames, positions), labelled.
std::vector<DescribedValue> describe_build(const Sequence& seq, const BuildDesc& desc);

// The stages of build_shgrid:
// checks desc (bands, kernel and the size of its raster) and returns the grid it builds over seq;
GridDesc build_grid(const Sequence& seq, const BuildDesc& desc);
// desc.buckets with `auto` directions resolved from the first readable frame header;
BucketDesc resolve_directions(const Sequence& seq, const BuildDesc& desc);
// projects and repairs every bucket of block k (in buf, from store.load_block(k, buf)) onto the grid:
// R is (3·G × D) column-major, D the block's buckets, bucket b0 + j in column j; origins[p] is probe
// p's position. Sums the buckets' statistics (repair_seconds: thread seconds, with busy_seconds).
struct BlockStats {
  int64_t rays = 0, uncovered = 0;
  double repair_seconds = 0, busy_seconds = 0;  // summed over threads
};
using BlockScratch = tbb::enumerable_thread_specific<ProjectScratch>;
BlockStats project_block(const BucketStore& store, int k, const std::vector<uint16_t>& buf, const GridDesc& grid,
                         const ProjectDesc& desc, const std::vector<Vec3>& origins, float* R, BlockScratch& scratch,
                         bool ball_parallax = true);  // rays start on the ball when the table has starts
// One block of the resampling, as the serial and the distributed build both run it: load block k,
// project its buckets (project_block) into R, and add its SH products into C (3·G × K, double).
struct BlockWork {
  BlockStats stats;
  double project_seconds = 0, accumulate_seconds = 0, gemm_flops = 0;
};
BlockWork resample_block(const BucketStore& store, int k, const GridDesc& grid, const ProjectDesc& desc,
                         const std::vector<Vec3>& origins, int bands, bool ball_parallax, std::vector<uint16_t>& buf,
                         std::vector<float>& R, BlockScratch& scratch, double* C);
// The cross-validated choice of kernel and resolution (desc.auto_kernel, desc.auto_grid) and the
// cross-validated error (desc.crossval), as the serial and the distributed build both make them, on
// the sorted store: sets rep.choice, crossval, crossval_buckets, t_choose, t_crossval, nx/ny/nz and
// kernel_cells, and moves grid and pd to the choice. Distributed: every rank calls it with its share
// of the blocks (crossval.h, CvShare) and gets the job's choice and error.
void cross_validate_build(const BucketStore& store, const std::vector<Vec3>& origins, const BuildDesc& desc,
                          GridDesc& grid, ProjectDesc& pd, BuildReport& rep, const CvShare& share = {});
// C (3·G × K, column-major, as accumulate_block leaves it) into the grid's coefficient layout.
void store_coefficients(const double* C, SHGrid& out);

}  // namespace ibl::ilf
