// Parallel loops on oneTBB. Bodies must be safe to run concurrently on disjoint ranges.
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace ibl {

// Calls body(i) for i in [begin, end) in parallel, `grain` indices at least per task.
template <typename F>
void parallel_for(int64_t begin, int64_t end, F&& body, int64_t grain = 1) {
  if (end <= begin) return;
  tbb::parallel_for(tbb::blocked_range<int64_t>(begin, end, grain), [&](const tbb::blocked_range<int64_t>& r) {
    for (int64_t i = r.begin(); i != r.end(); ++i) body(i);
  });
}

// Calls body(lo, hi) on disjoint chunks covering [begin, end).
template <typename F>
void parallel_chunks(int64_t begin, int64_t end, F&& body, int64_t grain = 1) {
  if (end <= begin) return;
  tbb::parallel_for(tbb::blocked_range<int64_t>(begin, end, grain),
                    [&](const tbb::blocked_range<int64_t>& r) { body(r.begin(), r.end()); });
}

// Deterministic parallel reduction: chunks of fixed size are reduced in a fixed order, so the
// result does not depend on the thread count or scheduling.
template <typename T, typename ChunkF, typename CombineF>
T parallel_reduce_fixed(int64_t begin, int64_t end, int64_t chunk, T init, ChunkF&& chunk_body, CombineF&& combine) {
  if (end <= begin) return init;
  int64_t nchunks = (end - begin + chunk - 1) / chunk;
  std::vector<T> partial(static_cast<size_t>(nchunks), init);
  parallel_for(0, nchunks, [&](int64_t c) {
    int64_t lo = begin + c * chunk, hi = std::min(end, lo + chunk);
    partial[static_cast<size_t>(c)] = chunk_body(lo, hi);
  });
  T acc = init;
  for (auto& p : partial) acc = combine(acc, p);
  return acc;
}

}  // namespace ibl
