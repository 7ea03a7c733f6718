#include "iblkit/ilf/subsample.h"

#include <atomic>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/parallel.h"
#include "iblkit/io/image_io.h"

namespace ibl::ilf {

double difference_energy(const Image& a, const Image& b, const sphere::Mapping& m) {
  if (a.width() != b.width() || a.height() != b.height())
    fail(ErrorKind::Value, "difference energy: frames of {}x{} and {}x{}", a.width(), a.height(), b.width(),
         b.height());
  double diff = 0, sum = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      double w = m.solid_angle(x, y);
      if (w <= 0) continue;
      double ya = luminance(a.rgb(x, y)), yb = luminance(b.rgb(x, y));
      diff += std::abs(ya - yb) * w;
      sum += 0.5 * (ya + yb) * w;
    }
  return sum > 0 ? diff / sum : 0.0;
}

void check_subsample_desc(const SubsampleDesc& desc) {
  if (!(desc.threshold >= 0) || !std::isfinite(desc.threshold))
    fail(ErrorKind::Value, "subsample: threshold {} must be a finite number ≥ 0", desc.threshold);
  if (!(desc.max_distance >= 0) || !std::isfinite(desc.max_distance))
    fail(ErrorKind::Value, "subsample: neighbour distance {} must be a finite number ≥ 0 metres", desc.max_distance);
}

std::vector<double> neighbour_energies(const Sequence& seq, const SubsampleDesc& desc, int i0, int i1,
                                       const ProgressFn& progress) {
  // E between consecutive probes, in parallel (each frame is read twice, by its two pairs).
  std::vector<double> e(size_t(std::max(i1 - i0, 0)), 1e300);
  std::atomic<int> done{0};
  parallel_for(i0, i1, [&](int64_t i) {
    const auto &pa = seq.probes[i], &pb = seq.probes[i + 1];
    if (length(pa.position - pb.position) <= desc.max_distance) {
      Image a, b;
      try {
        a = io::read_image(pa.image, {false, 3});
      } catch (const Error& err) {
        if (desc.skip_bad) return;
        fail(err.kind(), "{}: probe {}: field \"image\": {}", seq.manifest, i, err.what());
      }
      try {
        b = io::read_image(pb.image, {false, 3});
      } catch (const Error& err) {
        if (desc.skip_bad) return;
        fail(err.kind(), "{}: probe {}: field \"image\": {}", seq.manifest, i + 1, err.what());
      }
      if (a.width() != b.width() || a.height() != b.height())
        fail(ErrorKind::Value, "{}: probe {}: field \"image\": {}x{} differs from probe {}'s {}x{}", seq.manifest,
             i + 1, b.width(), b.height(), i, a.width(), a.height());
      sphere::Mapping m(seq.mapping, a.width(), a.height(), seq.dead_angle_deg);
      e[i - i0] = difference_energy(a, b, m);
    }
    ibl::report(progress, "subsample", double(++done) / (i1 - i0));
  });
  return e;
}

std::vector<int> keep_from_energies(int n, const std::vector<double>& e, double threshold) {
  std::vector<int> keep;
  if (n <= 2) {
    for (int i = 0; i < n; ++i) keep.push_back(i);
    return keep;
  }
  bool prev_dropped = false;
  keep.push_back(0);
  for (int i = 1; i < n - 1; ++i) {
    bool drop = !prev_dropped && e[i - 1] < threshold && e[i] < threshold;
    if (!drop) keep.push_back(i);
    prev_dropped = drop;
  }
  keep.push_back(n - 1);
  return keep;
}

std::vector<int> subsample(const Sequence& seq, const SubsampleDesc& desc, const ProgressFn& progress,
                           SubsampleReport* report) {
  check_subsample_desc(desc);
  int n = int(seq.probes.size());
  std::vector<double> e;
  if (n > 2) e = neighbour_energies(seq, desc, 0, n - 1, progress);
  auto keep = keep_from_energies(n, e, desc.threshold);
  if (report) *report = {int(keep.size()), n - int(keep.size())};
  return keep;
}

}  // namespace ibl::ilf
