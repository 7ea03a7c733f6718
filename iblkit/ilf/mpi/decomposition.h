// How the distributed ILF build (ilf/distributed.h) splits the work between N ranks: who owns which
// direction blocks, who reads which probe frames, in which rounds. Pure arithmetic on the direction
// table, the same on every rank (no MPI here, so the tests check it directly). Cost model: docs/ilf.md.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "iblkit/ilf/buckets.h"

namespace ibl::ilf::mpi {

struct Decomposition {
  int ranks = 1, probes = 0;
  // Rank q owns blocks [block_begin[q], block_begin[q+1]) — contiguous, balanced by sample slots —
  // and so sample slots [slot_begin[q], slot_begin[q+1]) of every probe.
  std::vector<int> block_begin;
  std::vector<int64_t> slot_begin;
  // Probes are read in chunks of `chunk` (the last one shorter): chunk g holds probes
  // [g·chunk, min((g+1)·chunk, probes)), and rank r reads chunks [chunk_begin[r], chunk_begin[r+1]),
  // one per round; every rank takes part in all `rounds` rounds (sending nothing when it has no chunk).
  int chunk = 1, chunks = 1, rounds = 1;
  std::vector<int> chunk_begin;

  int chunk_of(int rank, int round) const {  // global chunk rank reads in this round, −1 for none
    int g = chunk_begin[rank] + round;
    return g < chunk_begin[rank + 1] ? g : -1;
  }
  int chunk_probes(int g) const { return g < 0 ? 0 : std::min(chunk, probes - g * chunk); }
  int blocks_of(int rank) const { return block_begin[rank + 1] - block_begin[rank]; }
  int64_t slots_of(int rank) const { return slot_begin[rank + 1] - slot_begin[rank]; }
};

// Splits table t's blocks and `probes` frames between `ranks`. The chunk is the largest that keeps a
// rank's send and receive buffers of one round within an eighth of memory_bytes each (the serial sort
// uses a quarter for its one buffer) and gives every rank at least one chunk, and the element counts
// of one exchange within MPI's int.
Decomposition decompose(const DirectionTable& t, int probes, int ranks, size_t memory_bytes);

}  // namespace ibl::ilf::mpi
