// The collective steps of `ilf build` (build.h) when its work is split between the processes of a
// job. There is one build, build_shgrid, whose stages (grid, sub-sampling, sort, cross-validation,
// resampling, reduction) call these hooks where processes meet; the default Collective is the job of
// one process, where every hook is the identity, and ilf/mpi/ gives the MPI one. So the serial and
// the distributed build run the same code and cannot drift apart.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "iblkit/ilf/buckets.h"

namespace ibl::ilf {

// How the bucket sort (buckets.h) is split: which blocks this process writes, which probe chunks it
// reads in which round, and the index file that says its blocks are complete.
struct SortPlan {
  int chunk = 1;                       // probes per segment of every block file
  int rounds = 1;                      // read-and-write rounds every process takes part in
  int block_begin = 0, block_end = 0;  // the blocks this process writes (and later projects)
  std::string index = "index.json";    // this process's index file in the bucket folder
  std::string key_suffix;              // the split in the cache key ("" for one process)
  std::vector<int> chunk_of_round;     // the chunk this process reads in each round (−1: none)
  int chunk_probes(int g, int probes) const { return g < 0 ? 0 : std::min(chunk, probes - g * chunk); }
};

// One labelled value of a job's description ("--grid" = "24,24,24"); the processes of a job compare
// them (Collective::agree_on) before they work together.
using DescribedValue = std::pair<std::string, std::string>;

class Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const { return 0; }
  virtual int size() const { return 1; }

  // Runs f (local work, no collective calls) and lets every process learn whether it failed on any:
  // then every process throws the error of the lowest process that failed.
  virtual void agree(const std::function<void()>& f) { f(); }
  // Fails on every process, with one line naming the first value that differs and the processes'
  // values, unless every process passed the same description (labels and values).
  virtual void agree_on(const std::vector<DescribedValue>& description) {}

  // x[0, n) := its sum over the processes: on process 0 only (the others' x is left as it was), or
  // with `everywhere` on every process and the same bits on each.
  virtual void sum(double* x, int64_t n, bool everywhere) {}
  virtual void sum(int64_t* x, int n) {}
  virtual void sum_figures(double* x, int n) {}  // report figures: every process gets the sum (any rounding)
  virtual void max(double* x, int n) {}
  virtual void max(int64_t* x, int n) {}
  virtual void min(uint8_t* x, int n) {}
  virtual bool all(bool mine) { return mine; }
  // Every process's values in process order, on every process (counts[r]: how many process r gives).
  virtual std::vector<double> gather(const std::vector<double>& mine, const std::vector<int>& counts) { return mine; }
  virtual std::vector<std::string> gather(const std::vector<std::string>& mine) { return mine; }

  // The sort's split (a plan the same on every process) for table t of `probes` probes.
  virtual SortPlan plan_sort(const DirectionTable& t, int probes, size_t memory_bytes);
  // Round `round` of the sort: `chunk` holds this process's chunk of `pc` probes in the segment layout
  // over all of t's slots (scatter_probe_samples); write(g, pcs, segment, slot0) is called for every
  // chunk g of pcs probes whose samples of this process's blocks are now here, in segment layout over
  // the slots from slot0 on. The default: write(plan.chunk_of_round[round], pc, chunk, 0).
  virtual void exchange(const SortPlan& plan, const DirectionTable& t, int round, const uint16_t* chunk, int pc,
                        const std::function<void(int g, int pcs, const uint16_t* segment, int64_t slot0)>& write);
};

// The job of one process.
Collective& serial_collective();

// Shares of n items between `size` processes: process r takes [begin[r], begin[r+1]).
std::vector<int> split_evenly(int n, int size);

}  // namespace ibl::ilf
