#include "iblkit/ilf/mpi/mpi_collective.h"

#include <mpi.h>

#include <algorithm>
#include <thread>

#include <fmt/format.h>

namespace ibl::ilf::mpi {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The partial sums meet in pieces of 64 MiB (the counts of one call stay within MPI's int).
constexpr int64_t kReducePiece = int64_t(1) << 23;
constexpr int kTagHello = 7301, kTagVerdict = 7302;  // the handshake's messages

// x[0, n) := its sum over the ranks, on rank 0 (the others' x is left as it was).
void sum_on_root(double* x, int64_t n, int rank) {
  for (int64_t off = 0; off < n; off += kReducePiece) {
    int m = int(std::min(kReducePiece, n - off));
    if (rank == 0)
      MPI_Reduce(MPI_IN_PLACE, x + off, m, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    else
      MPI_Reduce(x + off, nullptr, m, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  }
}

// A description as one string: label US value RS …
std::string pack(const std::vector<DescribedValue>& d) {
  std::string s;
  for (const auto& [k, v] : d) s += k + '\x1f' + v + '\x1e';
  return s;
}
std::vector<DescribedValue> unpack(const std::string& s) {
  std::vector<DescribedValue> d;
  for (size_t i = 0; i < s.size();) {
    size_t us = s.find('\x1f', i), rs = s.find('\x1e', i);
    if (us == std::string::npos || rs == std::string::npos || us > rs) break;
    d.push_back({s.substr(i, us - i), s.substr(us + 1, rs - us - 1)});
    i = rs + 1;
  }
  return d;
}

// "" when every rank's description is rank 0's, else the line naming the first value that differs.
std::string compare(const std::vector<std::string>& packed) {
  std::vector<std::vector<DescribedValue>> d;
  for (const auto& p : packed) d.push_back(unpack(p));
  std::vector<std::string> labels;
  for (const auto& di : d)
    for (const auto& [k, v] : di)
      if (std::find(labels.begin(), labels.end(), k) == labels.end()) labels.push_back(k);
  auto value = [&](size_t r, const std::string& k) {
    for (const auto& [kk, v] : d[r])
      if (kk == k) return v;
    return std::string("(not given)");
  };
  for (const auto& k : labels) {
    std::string v0 = value(0, k), others;
    int shown = 0;
    for (size_t r = 1; r < d.size(); ++r) {
      std::string v = value(r, k);
      if (v == v0) continue;
      if (shown++ < 3) others += fmt::format(", rank {} has {}", r, v);
    }
    if (shown)
      return fmt::format(
          "the ranks of this MPI job disagree on {}: rank 0 has {}{}{} (start every rank with the same "
          "command line and inputs)",
          k, v0, others, shown > 3 ? fmt::format(" and {} more", shown - 3) : "");
  }
  return "";
}

std::string rank_list(const std::vector<int>& r) {
  std::string s;
  for (size_t i = 0; i < r.size() && i < 8; ++i) s += (i ? ", " : "") + std::to_string(r[i]);
  if (r.size() > 8) s += fmt::format(" and {} more", r.size() - 8);
  return s;
}

}  // namespace

MpiCollective::MpiCollective(double timeout_s) : timeout_s_(timeout_s) {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

void MpiCollective::settle(bool failed, ErrorKind kind, const std::string& msg) {
  int mine = failed ? rank_ : size_, first = size_;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size_) return;
  int hdr[2] = {int(kind), int(msg.size())};
  MPI_Bcast(hdr, 2, MPI_INT, first, MPI_COMM_WORLD);
  std::string m = rank_ == first ? msg : std::string(size_t(hdr[1]), '\0');
  MPI_Bcast(m.data(), hdr[1], MPI_CHAR, first, MPI_COMM_WORLD);
  throw AgreedError(ErrorKind(hdr[0]), m);
}

void MpiCollective::agree(const std::function<void()>& f) {
  bool failed = false;
  ErrorKind kind = ErrorKind::Internal;
  std::string msg;
  try {
    f();
  } catch (const AgreedError&) {
    throw;  // every rank raised it already
  } catch (const Error& e) {
    failed = true, kind = e.kind(), msg = e.what();
  } catch (const std::bad_alloc&) {
    failed = true, kind = ErrorKind::Value, msg = "out of memory (lower --memory or use more ranks)";
  } catch (const std::exception& e) {
    failed = true, msg = e.what();
  }
  settle(failed, kind, msg);
}

// The handshake, with point-to-point messages and a deadline instead of collectives (which would wait
// forever for a rank that never comes): every rank sends rank 0 its description, rank 0 compares them
// and sends every rank that came the verdict.
void MpiCollective::agree_on(const std::vector<DescribedValue>& description) {
  const std::string mine = pack(description);
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s_);
  auto poll = [&](int from, int tag, std::string* got) {
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(from, tag, MPI_COMM_WORLD, &flag, &st);
    if (!flag) return false;
    int n = 0;
    MPI_Get_count(&st, MPI_CHAR, &n);
    got->assign(size_t(n), '\0');
    MPI_Recv(got->data(), n, MPI_CHAR, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return true;
  };
  std::string verdict;
  if (rank_ == 0) {
    std::vector<std::string> got(static_cast<size_t>(size_));
    std::vector<char> came(static_cast<size_t>(size_), 0);
    got[0] = mine;
    came[0] = 1;
    int left = size_ - 1;
    while (left > 0) {
      for (int r = 1; r < size_; ++r)
        if (!came[r] && poll(r, kTagHello, &got[r])) came[r] = 1, --left;
      if (left == 0 || Clock::now() > deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::vector<int> missing;
    for (int r = 1; r < size_; ++r)
      if (!came[r]) missing.push_back(r);
    verdict = missing.empty() ? compare(got)
                              : fmt::format(
                                    "rank{} {} of this MPI job of {} did not take part within --mpi-timeout {:g} s (is "
                                    "every rank `iblkit ilf build` with the same options?)",
                                    missing.size() > 1 ? "s" : "", rank_list(missing), size_, timeout_s_);
    std::string sent = (missing.empty() ? "0" : "1") + verdict;
    for (int r = 1; r < size_; ++r)
      if (came[r]) MPI_Send(sent.data(), int(sent.size()), MPI_CHAR, r, kTagVerdict, MPI_COMM_WORLD);
    if (!missing.empty()) throw BrokenJob(verdict, true);
  } else {
    MPI_Request req;
    MPI_Isend(mine.data(), int(mine.size()), MPI_CHAR, 0, kTagHello, MPI_COMM_WORLD, &req);
    std::string got;
    // Rank 0 may wait up to the deadline for another rank before it answers.
    const auto answer_by = deadline + std::chrono::duration<double>(timeout_s_);
    while (!poll(0, kTagVerdict, &got)) {
      if (Clock::now() > answer_by) {
        MPI_Cancel(&req);
        throw BrokenJob(fmt::format("rank 0 of this MPI job of {} did not answer within --mpi-timeout {:g} s (is "
                                    "every rank `iblkit ilf build` with the same options?)",
                                    size_, timeout_s_),
                        true);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    MPI_Wait(&req, MPI_STATUS_IGNORE);
    if (!got.empty() && got[0] == '1') throw BrokenJob(got.substr(1), false);
    verdict = got.substr(1);
  }
  if (!verdict.empty()) throw AgreedError(ErrorKind::Value, verdict);
}

void MpiCollective::sum(double* x, int64_t n, bool everywhere) {
  auto t0 = Clock::now();
  sum_on_root(x, n, rank_);
  if (everywhere) {  // rank 0's sum, broadcast: MPI_Allreduce need not give every rank the same rounding
    for (int64_t off = 0; off < n; off += kReducePiece)
      MPI_Bcast(x + off, int(std::min(kReducePiece, n - off)), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    bytes_shared += size_ > 1 ? n * 8 : 0;
  } else {
    bytes_reduced += size_ > 1 ? n * 8 : 0;
    t_reduce += since(t0);
  }
}

void MpiCollective::sum(int64_t* x, int n) { MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD); }
void MpiCollective::sum_figures(double* x, int n) {
  MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
}
void MpiCollective::max(double* x, int n) { MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD); }
void MpiCollective::max(int64_t* x, int n) { MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD); }
void MpiCollective::min(uint8_t* x, int n) { MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_UINT8_T, MPI_MIN, MPI_COMM_WORLD); }
bool MpiCollective::all(bool mine) {
  int m = mine ? 1 : 0, a = 0;
  MPI_Allreduce(&m, &a, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return a != 0;
}

std::vector<double> MpiCollective::gather(const std::vector<double>& mine, const std::vector<int>& counts) {
  std::vector<int> displs(static_cast<size_t>(size_), 0);
  for (int r = 1; r < size_; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(size_t(displs[size_ - 1] + counts[size_ - 1]));
  MPI_Allgatherv(mine.data(), counts[rank_], MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  return all;
}

std::vector<std::string> MpiCollective::gather(const std::vector<std::string>& mine) {
  std::string packed;
  for (const auto& s : mine) packed += s + '\n';
  int n = int(packed.size());
  std::vector<int> counts(static_cast<size_t>(size_)), displs(static_cast<size_t>(size_), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < size_; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::string all(size_t(displs[size_ - 1] + counts[size_ - 1]), '\0');
  MPI_Allgatherv(packed.data(), n, MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR, MPI_COMM_WORLD);
  std::vector<std::string> out;
  for (size_t pos = 0; pos < all.size();) {
    size_t e = all.find('\n', pos);
    out.push_back(all.substr(pos, e - pos));
    pos = e + 1;
  }
  return out;
}

SortPlan MpiCollective::plan_sort(const DirectionTable& t, int probes, size_t memory_bytes) {
  decomposition = decompose(t, probes, size_, memory_bytes);
  const Decomposition& d = decomposition;
  SortPlan plan;
  plan.chunk = d.chunk;
  plan.rounds = d.rounds;
  plan.block_begin = d.block_begin[rank_];
  plan.block_end = d.block_begin[rank_ + 1];
  plan.index = fmt::format("index.rank{}of{}.json", rank_, size_);
  plan.key_suffix = fmt::format("-mpi{}x{}", size_, d.chunk);
  for (int c = 0; c < d.rounds; ++c) plan.chunk_of_round.push_back(d.chunk_of(rank_, c));
  recv_.assign(size_t(d.chunk) * size_ * d.slots_of(rank_) * 3, 0);
  return plan;
}

// The samples of rank q's slots to rank q (MPI_Alltoallv), then every received chunk written.
void MpiCollective::exchange(const SortPlan& plan, const DirectionTable& t, int round, const uint16_t* chunk, int pc,
                             const std::function<void(int, int, const uint16_t*, int64_t)>& write) {
  auto t0 = Clock::now();
  const Decomposition& d = decomposition;
  const int64_t my_slots = d.slots_of(rank_);
  std::vector<int> scount(static_cast<size_t>(size_)), sdispl(static_cast<size_t>(size_)),
      rcount(static_cast<size_t>(size_)), rdispl(static_cast<size_t>(size_));
  for (int q = 0; q < size_; ++q) {
    scount[q] = int(int64_t(pc) * d.slots_of(q) * 3);
    sdispl[q] = int(int64_t(pc) * d.slot_begin[q] * 3);
    int pcs = d.chunk_probes(d.chunk_of(q, round));
    rcount[q] = int(int64_t(pcs) * my_slots * 3);
    rdispl[q] = q == 0 ? 0 : rdispl[q - 1] + rcount[q - 1];
    if (q != rank_) {
      bytes_sent += int64_t(scount[q]) * 2;
      bytes_received += int64_t(rcount[q]) * 2;
    }
  }
  MPI_Alltoallv(chunk, scount.data(), sdispl.data(), MPI_UINT16_T, recv_.data(), rcount.data(), rdispl.data(),
                MPI_UINT16_T, MPI_COMM_WORLD);
  for (int s = 0; s < size_; ++s) {
    int gs = d.chunk_of(s, round), pcs = d.chunk_probes(gs);
    if (pcs > 0) write(gs, pcs, recv_.data() + rdispl[s], d.slot_begin[rank_]);
  }
  t_exchange += since(t0);
}

}  // namespace ibl::ilf::mpi
