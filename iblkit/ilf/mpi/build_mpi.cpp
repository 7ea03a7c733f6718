// The distributed ILF build (ilf/distributed.h) on MPI: the "mpi" plugin of the iblkit command. The
// build is build_shgrid itself (build.h), its stages meeting through MpiCollective (mpi_collective.h)
// with the decomposition of decomposition.h and the cost model of docs/ilf.md ("On a cluster"):
//   handshake  the ranks compare the job's description (options, sequence), with a deadline;
//   subsample  each rank the energies of its pairs of neighbours, MPI_Allgatherv of all of them;
//   sort       each rank its chunks of frames, MPI_Alltoallv of every block's samples to the rank that
//              owns the block, written there at their serial offsets (index.rankRofN.json marks them);
//   crossval   the cross-validated choice and error on the own blocks' sampled buckets, the partial
//              sums added on every rank (MPI_Reduce + MPI_Bcast);
//   resample   each rank its own blocks: projection, repair, SH products summed in double;
//   reduce     MPI_Reduce of the partial sums onto rank 0, which returns the grid.
#include <mpi.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <thread>

#include "iblkit/ilf/distributed.h"
#include "iblkit/ilf/mpi/mpi_collective.h"

namespace ibl::ilf::mpi {

namespace {

// Seconds a rank other than 0 waits after a failed job before it exits on its own (rank 0 reports, exits,
// and mpirun ends it sooner): long enough for rank 0 to print under any load, short enough not to hang.
constexpr int kWaitForRootReport = 20;

int64_t peak_rss_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoll(line.substr(6)) * 1024;
  return 0;
}

class Job final : public MpiJob {
 public:
  explicit Job(MpiCollective& team) : team_(team) {}
  int rank() const override { return team_.rank(); }
  int ranks() const override { return team_.size(); }
  void agree(const std::function<void()>& f) override { team_.agree(f); }
  SHGrid build(const Sequence& seq, const BuildDesc& desc, const ProgressFn& progress, BuildReport* report,
               DistributedReport* dreport) override;

 private:
  MpiCollective& team_;
};

SHGrid Job::build(const Sequence& seq, const BuildDesc& desc, const ProgressFn& progress, BuildReport* report,
                  DistributedReport* dreport) {
  BuildReport local;
  BuildReport& rep = report ? *report : local;
  DistributedReport dlocal;
  DistributedReport& dr = dreport ? *dreport : dlocal;
  dr = {};
  team_.t_exchange = team_.t_reduce = 0;
  team_.bytes_sent = team_.bytes_received = team_.bytes_reduced = team_.bytes_shared = 0;
  SHGrid out = build_shgrid(seq, desc, progress, &rep, &team_);
  // The whole job's figures: seconds and bytes of the slowest rank.
  double tmax[8] = {rep.t_read,       team_.t_exchange, rep.t_project,   rep.t_repair,
                    rep.t_accumulate, team_.t_reduce,   rep.t_subsample, rep.t_choose + rep.t_crossval};
  team_.max(tmax, 8);
  int64_t bmax[3] = {team_.bytes_sent, team_.bytes_received, peak_rss_bytes()};
  team_.max(bmax, 3);
  const Decomposition& d = team_.decomposition;
  dr.ranks = team_.size();
  dr.t_read = tmax[0];
  dr.t_exchange = tmax[1];
  dr.t_project = tmax[2];
  dr.t_repair = tmax[3];
  dr.t_accumulate = tmax[4];
  dr.t_reduce = tmax[5];
  dr.t_subsample = tmax[6];
  dr.t_crossval = tmax[7];
  dr.bytes_sent = bmax[0];
  dr.bytes_received = bmax[1];
  dr.peak_rss_bytes = bmax[2];
  dr.bytes_reduced = team_.bytes_reduced;
  dr.bytes_crossval = team_.bytes_shared;
  dr.chunk = d.chunk;
  dr.blocks_min = rep.blocks;
  dr.blocks_max = 0;
  for (int q = 0; q < d.ranks && !d.block_begin.empty(); ++q) {
    dr.blocks_min = std::min(dr.blocks_min, d.blocks_of(q));
    dr.blocks_max = std::max(dr.blocks_max, d.blocks_of(q));
  }
  rep.t_project = dr.t_project;
  rep.t_repair = dr.t_repair;
  rep.t_accumulate = dr.t_accumulate;
  return out;
}

// This process's rank as the launcher tells it (before MPI_Init), or −1.
int launcher_rank() {
  for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
    if (const char* s = std::getenv(v)) return std::atoi(s);
  return -1;
}

// MPI_Init, which waits for every rank of the job to start MPI: a rank that never does (a program
// that is not iblkit) would keep it waiting for ever. After timeout_s the process ends, rank 0 with
// the one line that says why (no error can be thrown out of MPI_Init; this is the one place the
// driver prints).
void init_with_deadline(double timeout_s) {
  int inited = 0;
  MPI_Initialized(&inited);
  if (inited) return;
  std::mutex mu;
  std::condition_variable cv;
  bool done = false;
  std::thread watchdog([&] {
    std::unique_lock lk(mu);
    if (cv.wait_for(lk, std::chrono::duration<double>(timeout_s), [&] { return done; })) return;
    if (launcher_rank() <= 0)
      std::fprintf(stderr,
                   "iblkit: error: MPI_Init did not complete within --mpi-timeout %g s: a rank of this job never "
                   "started MPI (is every rank `iblkit ilf build`?)\n",
                   timeout_s);
    std::_Exit(1);
  });
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  {
    std::lock_guard lk(mu);
    done = true;
  }
  cv.notify_one();
  watchdog.join();
}

void run(const MpiJobDesc& desc, const std::function<void(MpiJob&)>& body) {
  init_with_deadline(desc.timeout_s);
  bool failed = false;
  ErrorKind kind = ErrorKind::Internal;
  std::string msg;
  MpiCollective team(desc.timeout_s);
  Job job(team);
  try {
    // The handshake before any collective call (one would wait for ever for a rank that never comes).
    team.agree_on(desc.description);
    // The ranks on one node share its cores.
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
    int local = 1;
    MPI_Comm_size(node, &local);
    MPI_Comm_free(&node);
    int threads = std::max(1, tbb::info::default_concurrency() / local);
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    team.agree([&] { body(job); });
  } catch (const BrokenJob& e) {
    // A rank never came: MPI_Finalize would wait for it. Rank 0 (or a rank that found rank 0
    // missing) reports; ending without MPI_Finalize makes mpirun end the whole job.
    if (!e.report()) std::_Exit(1);
    throw AgreedError(ErrorKind::Value, e.what());
  } catch (const AgreedError& e) {
    failed = true;
    kind = e.kind();
    msg = e.what();
  }
  MPI_Finalize();
  if (failed) {
    if (team.rank() == 0) throw AgreedError(kind, msg);
    // Rank 0 reports the agreed error (main prints it) and exits non-zero, and mpirun then ends the
    // others. A rank that exited non-zero first would make mpirun end the job before rank 0 has printed
    // (seen under load: the job failed without a line), so the others wait for that, bounded.
    std::this_thread::sleep_for(std::chrono::seconds(kWaitForRootReport));
    std::exit(1);
  }
}

const detail::MpiDriver kDriver{run};
[[maybe_unused]] const bool kProvided = (detail::mpi_driver.provide(&kDriver), true);

}  // namespace

}  // namespace ibl::ilf::mpi
