#include "iblkit/ilf/mpi/decomposition.h"

#include <algorithm>
#include <climits>

#include "iblkit/core/error.h"

namespace ibl::ilf::mpi {

Decomposition decompose(const DirectionTable& t, int probes, int ranks, size_t memory_bytes) {
  if (ranks < 1 || probes < 1) fail(ErrorKind::Internal, "decomposition of {} probes over {} ranks", probes, ranks);
  Decomposition d;
  d.ranks = ranks;
  d.probes = probes;
  // Blocks: rank q's range starts at the first block whose slots begin at or after q/N of all slots.
  int64_t S = t.slots();
  d.block_begin.assign(size_t(ranks) + 1, t.blocks());
  d.block_begin[0] = 0;
  int k = 0;
  for (int q = 1; q < ranks; ++q) {
    int64_t target = S * q / ranks;
    while (k < t.blocks() && t.bucket_begin[t.block_begin[k]] < target) ++k;
    d.block_begin[q] = k;
  }
  d.slot_begin.resize(size_t(ranks) + 1);
  for (int q = 0; q <= ranks; ++q) d.slot_begin[q] = t.bucket_begin[t.block_begin[d.block_begin[q]]];
  // Chunks.
  size_t per_probe = size_t(std::max<int64_t>(S, 1)) * 3 * 2;
  size_t by_memory = std::max<size_t>(memory_bytes / 8 / per_probe, 1);
  size_t by_int = std::max<size_t>(size_t(INT_MAX) / (size_t(std::max<int64_t>(S, 1)) * 3), 1);
  size_t by_ranks = (size_t(probes) + ranks - 1) / ranks;
  d.chunk = int(std::max<size_t>(std::min({by_memory, by_int, by_ranks}), 1));
  d.chunks = (probes + d.chunk - 1) / d.chunk;
  d.chunk_begin.resize(size_t(ranks) + 1);
  for (int r = 0; r <= ranks; ++r) d.chunk_begin[r] = int(int64_t(d.chunks) * r / ranks);
  d.rounds = 0;
  for (int r = 0; r < ranks; ++r) d.rounds = std::max(d.rounds, d.chunk_begin[r + 1] - d.chunk_begin[r]);
  return d;
}

}  // namespace ibl::ilf::mpi
