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
  int kept = 0, dropped = 0;   // probe counts
};

// Relative difference energy of two frames of the same mapping:
//   E(a, b) = Σ_pixels |Y_a − Y_b|·Ω / (½·Σ_pixels (Y_a + Y_b)·Ω), Y the luminance, Ω the pixel solid angle.
double difference_energy(const Image& a, const Image& b, const sphere::Mapping& m);

// Returns the indices of the probes to keep, in order. The first and last probe are always kept, and
// two neighbours are never both dropped, so the density never falls below half the input's.
std::vector<int> subsample(const Sequence& seq, const SubsampleDesc& desc, const ProgressFn& progress = {},
                           SubsampleReport* report = nullptr);

}  // namespace ibl::ilf
