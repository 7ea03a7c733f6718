// The ILF build on a cluster (docs/ilf.md "On a cluster"): `mpirun -np N iblkit ilf build …`
// runs build_shgrid's phases split between the N processes of an MPI job and gives the serial build's
// grid (to float rounding). Ranks own contiguous ranges of direction blocks; each reads a disjoint
// slice of the probe frames, sends every block's samples to its owner (MPI_Alltoallv), cross-validates
// (and chooses kernel and grid) on the sampled buckets of its own blocks, those sums meeting on every
// rank, projects, repairs and accumulates its own blocks, and the partial SH sums meet on rank 0
// (MPI_Reduce), which returns the grid. MPI itself lives in the "mpi" plugin (ilf/mpi/, built with IBLKIT_WITH_MPI);
// this header is what the rest of iblkit sees of it.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "iblkit/core/error.h"
#include "iblkit/core/plugin.h"
#include "iblkit/ilf/build.h"

namespace ibl::ilf {

// Per-phase figures of a distributed build: seconds and bytes are the largest over the ranks (the
// ranks wait for the slowest at each exchange), counts are the whole job's.
struct DistributedReport {
  int ranks = 1;
  double t_subsample = 0;      // neighbour energies (each rank its pairs) and their all-gather
  double t_read = 0;           // decoding this rank's frames and scattering them into blocks
  double t_exchange = 0;       // MPI_Alltoallv of the samples to the blocks' owners, and writing them
  double t_project = 0;        // projection of the own blocks (repair included)
  double t_repair = 0;         // the repair's share of t_project
  double t_accumulate = 0;     // SH products of the own blocks
  double t_reduce = 0;         // MPI_Reduce of the partial SH sums onto rank 0
  double t_crossval = 0;       // the cross-validated choice and error (own blocks' sampled buckets, their sums' reduce)
  int64_t bytes_sent = 0;      // samples this rank sent to other ranks (half floats), largest rank
  int64_t bytes_received = 0;  // samples this rank received from other ranks, largest rank
  int64_t bytes_reduced = 0;   // partial SH sums a rank sends in the reduce (8 bytes per value)
  int64_t bytes_crossval = 0;  // partial cross-validation sums a rank sends in their reduce (8 bytes per value)
  int64_t peak_rss_bytes = 0;  // the largest rank's peak resident memory (VmHWM)
  int blocks_min = 0, blocks_max = 0;  // direction blocks per rank
  int chunk = 0;                       // probes per read-and-exchange round of one rank
};

// An error that every rank of the job raised together (the same message on each): rank 0 reports it,
// the others end quietly with status 1.
class AgreedError : public Error {
 public:
  using Error::Error;
};

// One rank of a running MPI job.
class MpiJob {
 public:
  virtual ~MpiJob() = default;
  virtual int rank() const = 0;
  virtual int ranks() const = 0;
  // Runs f on this rank, then all ranks learn whether it failed on any: if so, every rank throws the
  // AgreedError of the lowest rank that failed. f must not call collective operations.
  virtual void agree(const std::function<void()>& f) = 0;
  // build_shgrid(seq, desc) shared between the ranks; every rank calls it with the same arguments.
  // Rank 0 returns the grid, the others an empty one; `report` is the whole job's on every rank, and
  // `progress` (give it on rank 0) follows the whole job.
  virtual SHGrid build(const Sequence& seq, const BuildDesc& desc, const ProgressFn& progress, BuildReport* report,
                       DistributedReport* dreport) = 0;
};

// Whether a process manager (mpirun, srun with PMIx or PMI) started this process as a rank of a job.
bool launched_by_mpi();
// Whether this build has the distributed build (IBLKIT_WITH_MPI).
bool have_mpi();

// What the ranks of a job must agree on before they work together, and how long they wait for each
// other at that handshake.
struct MpiJobDesc {
  std::vector<DescribedValue> description;  // e.g. the command line's options and their values
  double timeout_s = 60;                    // a rank that has not come by then ends the job (--mpi-timeout)
};

// Initialises MPI (loading the "mpi" plugin), runs body on this rank and finalises MPI. First the
// ranks compare job.description (Collective::agree_on): where they differ, every rank ends with the
// one line that names the first differing value; where a rank does not come within job.timeout_s
// (it is not iblkit, or never started MPI), the job ends naming that rank (or, while MPI_Init itself
// waits, saying so). The ranks' thread pools share the node's cores (cores / ranks on the node
// each). An error any rank raises in body reaches every rank: rank 0 throws it (an AgreedError), the
// others exit with status 1 without a message, so the job prints it once and never hangs. Fails
// with Unsupported without MPI.
void run_mpi_job(const MpiJobDesc& job, const std::function<void(MpiJob&)>& body);

namespace detail {
struct MpiDriver {
  void (*run)(const MpiJobDesc& job, const std::function<void(MpiJob&)>& body);
};
extern plugin::Provided<MpiDriver> mpi_driver;
}  // namespace detail

}  // namespace ibl::ilf
