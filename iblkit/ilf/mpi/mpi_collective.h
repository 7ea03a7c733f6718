// ilf::Collective on MPI_COMM_WORLD: the hooks through which build_shgrid's stages split their work
// between the ranks of an MPI job (ilf/collective.h). Every failure is agreed between the ranks at
// the end of the step it happens in (MPI_Allreduce of who failed, MPI_Bcast of the message), so all
// ranks raise the same error together; agree_on compares the ranks' descriptions with a deadline.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/ilf/collective.h"
#include "iblkit/ilf/distributed.h"
#include "iblkit/ilf/mpi/decomposition.h"

namespace ibl::ilf::mpi {

// The job can no longer finish together (a rank never came to the handshake): this rank must end
// without MPI_Finalize, which would wait for the missing rank. `report`: this rank prints the message.
class BrokenJob : public Error {
 public:
  BrokenJob(const std::string& what, bool report) : Error(ErrorKind::Value, what), report_(report) {}
  bool report() const { return report_; }

 private:
  bool report_;
};

class MpiCollective final : public Collective {
 public:
  explicit MpiCollective(double timeout_s);
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void agree(const std::function<void()>& f) override;
  void agree_on(const std::vector<DescribedValue>& description) override;
  void sum(double* x, int64_t n, bool everywhere) override;
  void sum(int64_t* x, int n) override;
  void sum_figures(double* x, int n) override;
  void max(double* x, int n) override;
  void max(int64_t* x, int n) override;
  void min(uint8_t* x, int n) override;
  bool all(bool mine) override;
  std::vector<double> gather(const std::vector<double>& mine, const std::vector<int>& counts) override;
  std::vector<std::string> gather(const std::vector<std::string>& mine) override;
  SortPlan plan_sort(const DirectionTable& t, int probes, size_t memory_bytes) override;
  void exchange(const SortPlan& plan, const DirectionTable& t, int round, const uint16_t* chunk, int pc,
                const std::function<void(int, int, const uint16_t*, int64_t)>& write) override;

  // Collective: when any rank failed, every rank throws the lowest failing rank's error.
  void settle(bool failed, ErrorKind kind, const std::string& msg);

  // What the job spent where (this rank's): the sort's exchanges and the partial sums' reductions.
  double t_exchange = 0, t_reduce = 0;
  int64_t bytes_sent = 0, bytes_received = 0, bytes_reduced = 0, bytes_shared = 0;
  Decomposition decomposition;  // of the last sort

 private:
  int rank_ = 0, size_ = 1;
  double timeout_s_ = 60;
  std::vector<uint16_t> recv_;
};

}  // namespace ibl::ilf::mpi
