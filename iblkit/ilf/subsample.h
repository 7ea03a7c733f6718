// Step 1 of `ilf build` (optional): adaptive sub-sampling of a probe sequence ([1] §5.1). A probe is
// redundant when it is similar to both neighbours in the sequence — the energy of the absolute
// difference of their images is small — and close to both in position.
#pragma once
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/ilf/sequence.h"

namespace ibl::ilf {

struct SubsampleDesc {
  double threshold = 0.05;     // drop when relative difference energy E to both neighbours is below this
  double max_distance = 0.05;  // … and both neighbours lie within this many metres
  bool skip_bad = false;       // a frame that cannot be read keeps its neighbours (the bucket sort skips it)
};

struct SubsampleReport {
  int kept = 0, dropped = 0;  // probe counts
};

// Relative difference energy of two frames of the same mapping:
//   E(a, b) = Σ_pixels |Y_a − Y_b|·Ω / (½·Σ_pixels (Y_a + Y_b)·Ω), Y the luminance, Ω the pixel solid angle.
double difference_energy(const Image& a, const Image& b, const sphere::Mapping& m);

// Returns the indices of the probes to keep, in order. The first and last probe are always kept, and
// two neighbours are never both dropped, so the density never falls below half the input's.
std::vector<int> subsample(const Sequence& seq, const SubsampleDesc& desc, const ProgressFn& progress = {},
                           SubsampleReport* report = nullptr);

// The pieces of subsample, for drivers that split the pairs between processes (ilf/mpi/):
// checks desc's values (the error subsample gives);
void check_subsample_desc(const SubsampleDesc& desc);
// E(probe i, probe i+1) for the pairs i in [i0, i1), 1e300 where the two lie farther apart than
// max_distance or a frame is skipped (progress from 0 to 1 over these pairs);
std::vector<double> neighbour_energies(const Sequence& seq, const SubsampleDesc& desc, int i0, int i1,
                                       const ProgressFn& progress = {});
// the probes to keep of n, given E of every pair (n − 1 values).
std::vector<int> keep_from_energies(int n, const std::vector<double>& e, double threshold);

}  // namespace ibl::ilf
