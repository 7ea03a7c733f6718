// Step 3 and 4 of `ilf build`: radiance projection of one direction bucket onto every grid point
// ([1] §3.2), done on the plane perpendicular to the bucket's direction instead of by marching rays,
// and the repair of grid points that no ray reached ([1] §3.3, and a pull–push on the plane).
#pragma once
#include <cstdint>
#include <vector>

#include "iblkit/ilf/grid.h"

namespace ibl::ilf {

enum class Repair {
  None,      // leave uncovered grid points at zero radiance
  Mip,       // [1] §3.3: box-filtered 3D mip levels, trilinear lookup in the finest level with data
  PullPush,  // normalised-convolution pull–push on the 2D plane of the rays (Gortler et al. 1996)
};
const char* repair_name(Repair r);
Repair parse_repair(const std::string& s);  // none, mip, pullpush (or pull-push); throws ibl::Error otherwise

struct ProjectDesc {
  double kernel_cells = 3.0;    // Gaussian kernel support diameter in grid cells ([1] §5.2 uses 3)
  double raster_cells = 0.5;    // pixel size of the plane raster in grid cells (smaller = exacter, slower)
  Repair repair = Repair::Mip;  // how grid points without a ray are filled (mip measured better overall: docs/ilf.md)
};

// The rays of one bucket: n_dirs directions × n_probes origins, radiance per (probe, direction).
struct BucketRays {
  const float* dirs = nullptr;      // n_dirs world directions (3 floats each)
  const double* weights = nullptr;  // n_dirs solid angles (to form the mean direction)
  const float* starts = nullptr;    // optional: n_dirs offsets (3 floats) of each direction's ray start
                                    // from its probe's origin (a mirror ball's reflection points)
  int n_dirs = 0;
  const Vec3* origins = nullptr;   // n_probes capture positions
  const uint8_t* valid = nullptr;  // n_probes flags (0 = skipped probe)
  int n_probes = 0;
  // radiance(p) returns the 3·n_dirs floats of probe p (RGB per direction of the bucket).
  const float* (*radiance)(const void* ctx, int p) = nullptr;
  const void* ctx = nullptr;
};

// Cross-validation of one bucket (ilf/crossval.h): the probes are split into folds; the rays of each
// fold are splatted into a raster of their own, so that the estimate without fold f is the sum over
// all folds minus fold f's, read at the 8 grid points around each probe of f (its trilinear cell, as
// SHGrid::coeffs_at reads it), shifted by the bucket's mean start offset when rays start on a ball.
struct CvBucket {
  int n_folds = 0;                // ≥ 2
  const uint8_t* fold = nullptr;  // n_probes: the fold of each probe
  const int32_t* cell = nullptr;  // n_probes × 3: the lower corner (i, j, k) of the probe's cell
  const float* frac = nullptr;    // n_probes × 3: its trilinear fractions in the cell
  float* pred = nullptr;          // out: pred[c·stride + p], the estimate without p's fold
  float* own = nullptr;           // out: own[c·stride + p], p's own solid-angle-weighted mean radiance
  int64_t stride = 0;
};

struct ProjectStats {
  int64_t rays = 0;           // rays splatted
  int64_t uncovered = 0;      // grid points no ray reached (repaired)
  double repair_seconds = 0;  // time spent in the repair (pull–push or mip), this thread
};

// Per-thread scratch, reused across buckets.
struct ProjectScratch {
  std::vector<float> num, den, tmp;  // plane rasters and pyramid storage
  std::vector<float> rad;            // per-grid-point radiance before the 3D repair
  std::vector<uint8_t> covered;
  std::vector<float> fnum, fden;  // cross-validation: one raster per fold
  std::vector<float> pyr;         // cross-validation: box pyramid of one fold's complement
};

// Writes the bucket's radiance at grid point g, channel c into out[c·out_stride + g].
// With `cv`, the held-out estimates (CvBucket) instead: `out` is not written, nothing is repaired.
ProjectStats project_bucket(const GridDesc& grid, const BucketRays& rays, const ProjectDesc& desc, float* out,
                            int64_t out_stride, ProjectScratch& scratch, const CvBucket* cv = nullptr);

// [1] §3.3 on one channel set: values (3 channels, stride `stride`) at the grid's points, covered[g]
// says which hold data. Fills every uncovered point from the finest box-filtered mip level whose
// trilinear neighbourhood holds data. Returns the number of points filled.
int64_t repair_mip(const GridDesc& grid, float* values, int64_t stride, const uint8_t* covered);

}  // namespace ibl::ilf
