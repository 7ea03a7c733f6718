// The distributed ILF build (ilf/distributed.h) on MPI: the "mpi" plugin of the iblkit command.
// Phases, each from the serial builder (build.h, buckets.h, subsample.h), with the decomposition of
// decomposition.h and the cost model of docs/ilf.md ("On a cluster"):
//   subsample  each rank the energies of its pairs of neighbours, MPI_Allgatherv of all of them;
//   read       each rank its chunks of frames, scattered into the block-file layout (half floats);
//   exchange   per round MPI_Alltoallv: every block's samples to the rank owning it, written there
//              into the block files at their serial offsets (index.rankRofN.json marks them done);
//   crossval   the cross-validated choice and error (crossval.h) on the sampled buckets of the own
//              blocks, the partial sums added on every rank (MPI_Reduce + MPI_Bcast);
//   project    each rank its own blocks: projection, repair, SH products summed in double;
//   reduce     MPI_Reduce of the partial sums onto rank 0, which returns the grid.
// Every failure is agreed between the ranks at the end of the step it happens in (MPI_Allreduce of
// who failed, MPI_Bcast of the message), so all ranks raise the serial build's error together.
#include <fcntl.h>
#include <mpi.h>
#include <unistd.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>

#include <nlohmann/json.hpp>

#include "iblkit/core/json_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/ilf/distributed.h"
#include "iblkit/ilf/mpi/decomposition.h"

namespace ibl::ilf::mpi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int64_t peak_rss_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoll(line.substr(6)) * 1024;
  return 0;
}

// Writes n halves at byte offset `offset` of file `path` (which exists).
void write_at(const std::string& path, const uint16_t* data, size_t n, int64_t offset) {
  int fd = ::open(path.c_str(), O_WRONLY);
  if (fd < 0) fail(ErrorKind::Io, "{}: cannot open bucket block", path);
  const char* p = reinterpret_cast<const char*>(data);
  size_t left = n * 2;
  while (left > 0) {
    ssize_t w = ::pwrite(fd, p, left, offset);
    if (w <= 0) {
      ::close(fd);
      fail(ErrorKind::Io, "{}: write failed (disk full?)", path);
    }
    p += w;
    left -= size_t(w);
    offset += w;
  }
  ::close(fd);
}

// What a call ended in: nothing, an error of this rank, or an error every rank already agreed on.
struct Outcome {
  bool failed = false, agreed = false;
  ErrorKind kind = ErrorKind::Internal;
  std::string msg;
};
Outcome run_caught(const std::function<void()>& f) {
  Outcome r;
  try {
    f();
  } catch (const AgreedError& e) {
    r = {true, true, e.kind(), e.what()};
  } catch (const Error& e) {
    r = {true, false, e.kind(), e.what()};
  } catch (const std::exception& e) {
    r = {true, false, ErrorKind::Internal, e.what()};
  }
  return r;
}

class Job final : public MpiJob {
 public:
  Job() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  int rank() const override { return rank_; }
  int ranks() const override { return size_; }

  void agree(const std::function<void()>& f) override {
    Outcome r = run_caught(f);
    settle(r.failed, r.kind, r.msg);
  }

  // Collective: when any rank failed, every rank throws the lowest failing rank's error.
  void settle(bool failed, ErrorKind kind, const std::string& msg) {
    int mine = failed ? rank_ : size_, first = size_;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == size_) return;
    int hdr[2] = {int(kind), int(msg.size())};
    MPI_Bcast(hdr, 2, MPI_INT, first, MPI_COMM_WORLD);
    std::string m = rank_ == first ? msg : std::string(size_t(hdr[1]), '\0');
    MPI_Bcast(m.data(), hdr[1], MPI_CHAR, first, MPI_COMM_WORLD);
    throw AgreedError(ErrorKind(hdr[0]), m);
  }

  SHGrid build(const Sequence& seq, const BuildDesc& desc, const ProgressFn& progress, BuildReport* report,
               DistributedReport* dreport) override;

 private:
  int rank_ = 0, size_ = 1;
};

// Every rank's strings, in rank order, on every rank.
std::vector<std::string> all_gather_lines(const std::vector<std::string>& mine, int ranks) {
  std::string packed;
  for (const auto& s : mine) packed += s + '\n';
  int n = int(packed.size());
  std::vector<int> counts(static_cast<size_t>(ranks)), displs(static_cast<size_t>(ranks), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < ranks; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::string all(size_t(displs[ranks - 1] + counts[ranks - 1]), '\0');
  MPI_Allgatherv(packed.data(), n, MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR, MPI_COMM_WORLD);
  std::vector<std::string> out;
  size_t pos = 0;
  while (pos < all.size()) {
    size_t e = all.find('\n', pos);
    out.push_back(all.substr(pos, e - pos));
    pos = e + 1;
  }
  return out;
}

// The partial sums meet in pieces of 64 MiB (the counts of one call stay within MPI's int).
constexpr int64_t kReducePiece = int64_t(1) << 23;

// x[0, n) := its sum over the ranks, on rank 0 (the others' x is left as it was).
void sum_on_root(double* x, int64_t n) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  for (int64_t off = 0; off < n; off += kReducePiece) {
    int m = int(std::min(kReducePiece, n - off));
    if (rank == 0)
      MPI_Reduce(MPI_IN_PLACE, x + off, m, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    else
      MPI_Reduce(x + off, nullptr, m, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  }
}

// x[0, n) := its sum over the ranks, on every rank and the same bits on each: rank 0's sum, broadcast
// (MPI_Allreduce need not give every rank the same rounding, and the ranks must make the same choice).
void sum_on_every_rank(double* x, int64_t n) {
  sum_on_root(x, n);
  for (int64_t off = 0; off < n; off += kReducePiece)
    MPI_Bcast(x + off, int(std::min(kReducePiece, n - off)), MPI_DOUBLE, 0, MPI_COMM_WORLD);
}

SHGrid Job::build(const Sequence& seq_in, const BuildDesc& desc, const ProgressFn& progress, BuildReport* report,
                  DistributedReport* dreport) {
  auto t_all = Clock::now();
  BuildReport local;
  BuildReport& rep = report ? *report : local;
  DistributedReport dlocal;
  DistributedReport& dr = dreport ? *dreport : dlocal;
  rep = {};
  dr = {};
  dr.ranks = size_;
  const bool root = rank_ == 0;
  GridDesc grid;
  SHGrid out;
  agree([&] {
    grid = build_grid(seq_in, desc);
    if (root) out = SHGrid(grid, desc.bands);
  });
  rep.probes_in = int(seq_in.probes.size());

  // Sub-sampling: each rank the energies of its pairs.
  Sequence seq = seq_in;
  if (desc.subsample) {
    auto t0 = Clock::now();
    SubsampleDesc sd = *desc.subsample;
    sd.skip_bad = sd.skip_bad || desc.buckets.skip_bad;
    agree([&] { check_subsample_desc(sd); });
    int n = int(seq_in.probes.size());
    std::vector<double> e;
    if (n > 2) {
      int pairs = n - 1;
      std::vector<int> counts(static_cast<size_t>(size_)), displs(static_cast<size_t>(size_));
      for (int r = 0; r < size_; ++r) {
        displs[r] = int(int64_t(pairs) * r / size_);
        counts[r] = int(int64_t(pairs) * (r + 1) / size_) - displs[r];
      }
      std::vector<double> mine;
      agree([&] {
        mine = neighbour_energies(seq_in, sd, displs[rank_], displs[rank_] + counts[rank_],
                                  root ? progress : ProgressFn{});
      });
      e.resize(static_cast<size_t>(pairs));
      MPI_Allgatherv(mine.data(), counts[rank_], MPI_DOUBLE, e.data(), counts.data(), displs.data(), MPI_DOUBLE,
                     MPI_COMM_WORLD);
    }
    auto keep = keep_from_energies(n, e, sd.threshold);
    seq.probes.clear();
    for (int i : keep) seq.probes.push_back(seq_in.probes[i]);
    rep.subsampled_out = n - int(keep.size());
    dr.t_subsample = rep.t_subsample = since(t0);
  }

  // The direction table, the same on every rank (and as in the serial build).
  auto t_sort = Clock::now();
  BucketDesc bd;
  DirectionTable t;
  int w = 0, h = 0;
  int P = int(seq.probes.size());
  agree([&] {
    bd = resolve_directions(seq, desc);
    if (bd.dir.empty()) fail(ErrorKind::Value, "direction buckets: no folder given for the block files");
    std::error_code ec;
    fs::create_directories(bd.dir, ec);
    if (ec) fail(ErrorKind::Io, "{}: cannot create the bucket folder ({})", bd.dir, ec.message());
    sequence_frame_size(seq, bd.skip_bad, &w, &h);
    t = make_direction_table(seq, w, h, bd, P);
  });
  Decomposition d = decompose(t, P, size_, bd.memory_bytes);
  dr.chunk = d.chunk;
  const int kb0 = d.block_begin[rank_], kb1 = d.block_begin[rank_ + 1];
  const int64_t my_s0 = d.slot_begin[rank_], my_slots = d.slots_of(rank_);
  auto block_slots = [&](int k) { return t.bucket_begin[t.block_begin[k + 1]] - t.bucket_begin[t.block_begin[k]]; };

  // Reuse: every rank's blocks of an identical earlier run (same ranks, same chunk) are complete.
  std::string key = fmt::format("{}-mpi{}x{}", bucket_cache_key(seq, bd, w, h), size_, d.chunk);
  std::string index = (fs::path(bd.dir) / fmt::format("index.rank{}of{}.json", rank_, size_)).string();
  std::vector<uint8_t> valid;
  std::vector<std::string> reasons;
  int skipped = 0;
  int mine_ok = 0;
  if (bd.reuse && fs::exists(index)) {
    try {
      std::ifstream in(index);
      json j = json::parse(in);
      bool ok = j.value("key", "") == key && j.value("first_block", -1) == kb0 && j.value("end_block", -1) == kb1;
      for (int k = kb0; ok && k < kb1; ++k) {
        auto path = BucketStore::block_path(bd.dir, k);
        ok = fs::exists(path) && fs::file_size(path) == size_t(block_slots(k)) * P * 6;
      }
      if (ok) {
        valid = j["valid"].get<std::vector<uint8_t>>();
        skipped = j.value("skipped", 0);
        reasons = j.value("reasons", std::vector<std::string>{});
        mine_ok = int(valid.size()) == P;
      }
    } catch (const std::exception&) {
      mine_ok = 0;  // an unreadable index means the files are rebuilt
    }
  }
  int all_ok = 0;
  MPI_Allreduce(&mine_ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  rep.buckets_reused = all_ok != 0;
  if (!all_ok) {
    agree([&] {
      std::error_code ec;
      fs::remove(index, ec);
      for (int k = kb0; k < kb1; ++k) {
        FILE* f = std::fopen(BucketStore::block_path(bd.dir, k).c_str(), "wb");
        if (!f) fail(ErrorKind::Io, "{}: cannot create bucket block", BucketStore::block_path(bd.dir, k));
        std::fclose(f);
      }
    });
    valid.assign(size_t(P), 1);
    std::vector<std::pair<int, std::string>> skips;
    std::vector<uint16_t> sendbuf(size_t(d.chunk) * t.slots() * 3);
    std::vector<uint16_t> recvbuf(size_t(d.chunk) * size_ * my_slots * 3);
    std::vector<int> scount(static_cast<size_t>(size_)), sdispl(static_cast<size_t>(size_)),
        rcount(static_cast<size_t>(size_)), rdispl(static_cast<size_t>(size_));
    int64_t done_all = 0;
    for (int c = 0; c < d.rounds; ++c) {
      // Read this rank's chunk of the round.
      auto t0 = Clock::now();
      int g = d.chunk_of(rank_, c), pc = d.chunk_probes(g), p0 = g < 0 ? 0 : g * d.chunk;
      int bad_probe = -1;
      std::string bad_msg, fatal;
      ErrorKind fatal_kind = ErrorKind::Internal;
      std::mutex mu;
      try {
        parallel_for(0, pc, [&](int64_t i) {
          int p = p0 + int(i);
          std::vector<float> rgb;
          std::string msg = read_probe_samples(seq, p, t, bd, rgb);
          if (!msg.empty()) {
            std::lock_guard lk(mu);
            if (!bd.skip_bad) {
              if (bad_probe < 0 || p < bad_probe) {
                bad_probe = p;
                bad_msg = msg;
              }
            } else {
              valid[p] = 0;
              skips.push_back({p, msg});
            }
          }
          scatter_probe_samples(t, rgb.data(), pc, int(i), sendbuf.data());
        });
      } catch (const Error& e) {
        fatal = e.what();
        fatal_kind = e.kind();
      } catch (const std::exception& e) {
        fatal = e.what();
      }
      if (fatal.empty() && bad_probe >= 0) {
        fatal = bad_msg + " (skip_bad skips such probes)";
        fatal_kind = ErrorKind::Value;
      }
      settle(!fatal.empty(), fatal_kind, fatal);
      dr.t_read += since(t0);
      // Exchange: the samples of rank q's slots to rank q.
      auto t1 = Clock::now();
      int64_t sent = 0, received = 0;
      for (int q = 0; q < size_; ++q) {
        scount[q] = int(int64_t(pc) * d.slots_of(q) * 3);
        sdispl[q] = int(int64_t(pc) * d.slot_begin[q] * 3);
        int pcs = d.chunk_probes(d.chunk_of(q, c));
        rcount[q] = int(int64_t(pcs) * my_slots * 3);
        rdispl[q] = q == 0 ? 0 : rdispl[q - 1] + rcount[q - 1];
        if (q != rank_) {
          sent += int64_t(scount[q]) * 2;
          received += int64_t(rcount[q]) * 2;
        }
      }
      MPI_Alltoallv(sendbuf.data(), scount.data(), sdispl.data(), MPI_UINT16_T, recvbuf.data(), rcount.data(),
                    rdispl.data(), MPI_UINT16_T, MPI_COMM_WORLD);
      dr.bytes_sent += sent;
      dr.bytes_received += received;
      agree([&] {
        for (int s = 0; s < size_; ++s) {
          int gs = d.chunk_of(s, c), pcs = d.chunk_probes(gs);
          if (pcs == 0) continue;
          for (int k = kb0; k < kb1; ++k) {
            int64_t s0k = t.bucket_begin[t.block_begin[k]], nk = block_slots(k);
            const uint16_t* src = recvbuf.data() + rdispl[s] + size_t(pcs) * size_t(s0k - my_s0) * 3;
            write_at(BucketStore::block_path(bd.dir, k), src, size_t(pcs) * nk * 3, int64_t(gs) * d.chunk * nk * 6);
          }
        }
      });
      int64_t done = pc;
      MPI_Allreduce(MPI_IN_PLACE, &done, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
      done_all += done;
      dr.t_exchange += since(t1);
      if (root) ibl::report(progress, "sort", 0.9 * double(done_all) / P);
    }
    // Bad frames skipped anywhere: every rank learns them, in probe order.
    MPI_Allreduce(MPI_IN_PLACE, valid.data(), P, MPI_UINT8_T, MPI_MIN, MPI_COMM_WORLD);
    std::sort(skips.begin(), skips.end());
    std::vector<std::string> mine;
    for (auto& s : skips) mine.push_back(s.second);
    reasons = all_gather_lines(mine, size_);
    skipped = int(reasons.size());
    if (skipped == P) throw AgreedError(ErrorKind::Value, fmt::format("{}: every probe was skipped", seq.manifest));
    agree([&] {
      json j = {{"key", key},         {"chunk", d.chunk},       {"valid", valid},       {"skipped", skipped},
                {"reasons", reasons}, {"first_block", kb0},     {"end_block", kb1},     {"width", w},
                {"height", h},        {"buckets", t.buckets()}, {"blocks", t.blocks()}, {"ranks", size_}};
      write_json_file(index, j, -1);
    });
  }
  if (root) ibl::report(progress, "sort", 1.0);
  rep.t_sort = since(t_sort);
  rep.skipped = skipped;
  rep.skip_reasons = reasons;
  rep.octahedral = bd.octahedral;
  rep.buckets = t.buckets();
  rep.blocks = t.blocks();
  rep.probes_used = P - skipped;

  // The store of this rank's blocks (the others' block files are not touched) and the probes' positions.
  std::optional<BucketStore> store;
  agree([&] { store.emplace(BucketStore::open(bd.dir, t, P, d.chunk, valid)); });
  std::vector<Vec3> origins(static_cast<size_t>(P));
  for (int p = 0; p < P; ++p) origins[p] = seq.probes[p].position;

  // The cross-validated choice and error, as the serial build makes them: each rank evaluates the
  // sampled buckets of its own blocks, the partial sums are added over the job (every rank gets them,
  // so every rank makes the same choice) and every rank continues with the chosen kernel and grid.
  auto tcv = Clock::now();
  ProjectDesc pd = desc.project;
  int64_t cv_values = 0;
  CvShare share{kb0, kb1, [this](const std::function<void()>& f) { agree(f); },
                [&](double* x, size_t n) {
                  sum_on_every_rank(x, int64_t(n));
                  cv_values += int64_t(n);
                }};
  cross_validate_build(*store, origins, desc, grid, pd, rep, share);
  if (root && (grid.nx != out.grid().nx || grid.ny != out.grid().ny || grid.nz != out.grid().nz))
    out = SHGrid(grid, desc.bands);
  rep.ball_radius = desc.ball_parallax && !t.start.empty() ? seq.ball.radius : 0.0;
  dr.t_crossval = since(tcv);
  dr.bytes_crossval = size_ > 1 ? cv_values * 8 : 0;

  // Project, repair and accumulate the own blocks.
  int K = desc.bands * desc.bands;
  int64_t G = grid.count(), rows = 3 * G;
  std::vector<double> C;
  double busy_s = 0, repair_s = 0;
  int64_t counts[2] = {0, 0};  // rays, uncovered
  agree([&] {
    C.assign(size_t(rows) * K, 0.0);
    std::vector<float> R;
    std::vector<uint16_t> buf;
    BlockScratch scratch;
    for (int k = kb0; k < kb1; ++k) {
      auto w = resample_block(*store, k, grid, pd, origins, desc.bands, desc.ball_parallax, buf, R, scratch, C.data());
      counts[0] += w.stats.rays;
      counts[1] += w.stats.uncovered;
      busy_s += w.stats.busy_seconds;
      repair_s += w.stats.repair_seconds;
      dr.t_project += w.project_seconds;
      rep.gemm_flops += w.gemm_flops;
      dr.t_accumulate += w.accumulate_seconds;
      if (root) ibl::report(progress, "resample", double(k - kb0 + 1) / std::max(kb1 - kb0, 1));
    }
  });
  dr.t_repair = busy_s > 0 ? dr.t_project * repair_s / busy_s : 0.0;

  // Reduce the partial sums onto rank 0, in pieces of 64 MiB.
  auto tr = Clock::now();
  sum_on_root(C.data(), rows * K);
  dr.bytes_reduced = size_ > 1 ? rows * K * 8 : 0;
  if (root) store_coefficients(C.data(), out);
  std::vector<double>().swap(C);
  dr.t_reduce = since(tr);

  // The whole job's figures.
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &rep.gemm_flops, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  double tmax[8] = {dr.t_read,       dr.t_exchange, dr.t_project,   dr.t_repair,
                    dr.t_accumulate, dr.t_reduce,   dr.t_subsample, dr.t_crossval};
  MPI_Allreduce(MPI_IN_PLACE, tmax, 8, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  dr.t_read = tmax[0];
  dr.t_exchange = tmax[1];
  dr.t_project = tmax[2];
  dr.t_repair = tmax[3];
  dr.t_accumulate = tmax[4];
  dr.t_reduce = tmax[5];
  dr.t_subsample = tmax[6];
  dr.t_crossval = tmax[7];
  int64_t bmax[4] = {dr.bytes_sent, dr.bytes_received, peak_rss_bytes(), 0};
  MPI_Allreduce(MPI_IN_PLACE, bmax, 4, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
  dr.bytes_sent = bmax[0];
  dr.bytes_received = bmax[1];
  dr.peak_rss_bytes = bmax[2];
  dr.blocks_min = t.blocks();
  dr.blocks_max = 0;
  for (int q = 0; q < size_; ++q) {
    dr.blocks_min = std::min(dr.blocks_min, d.blocks_of(q));
    dr.blocks_max = std::max(dr.blocks_max, d.blocks_of(q));
  }
  rep.samples = counts[0];
  rep.uncovered = counts[1];
  rep.fraction_uncovered = double(rep.uncovered) / (double(G) * t.buckets());
  rep.t_project = dr.t_project;
  rep.t_repair = dr.t_repair;
  rep.t_accumulate = dr.t_accumulate;
  rep.t_total = since(t_all);
  return out;
}

void run(const std::function<void(MpiJob&)>& body) {
  int inited = 0;
  MPI_Initialized(&inited);
  if (!inited) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  }
  // The ranks on one node share its cores.
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int local = 1;
  MPI_Comm_size(node, &local);
  MPI_Comm_free(&node);
  int threads = std::max(1, tbb::info::default_concurrency() / local);
  bool failed = false, agreed = false;
  ErrorKind kind = ErrorKind::Internal;
  std::string msg;
  Job job;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    Outcome r = run_caught([&] { body(job); });
    failed = r.failed;
    agreed = r.agreed;
    kind = r.kind;
    msg = r.msg;
    if (!agreed) {
      try {
        job.settle(failed, kind, msg);
      } catch (const AgreedError& e) {
        failed = true;
        kind = e.kind();
        msg = e.what();
      }
    }
  }
  MPI_Finalize();
  if (failed) {
    if (job.rank() == 0) throw AgreedError(kind, msg);
    std::exit(1);
  }
}

const detail::MpiDriver kDriver{run};
[[maybe_unused]] const bool kProvided = (detail::mpi_driver.provide(&kDriver), true);

}  // namespace

}  // namespace ibl::ilf::mpi
