#include "iblkit/ilf/buckets.h"

#include <Imath/half.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <numeric>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/ilf/collective.h"
#include "iblkit/io/image_io.h"

namespace ibl::ilf {
namespace fs = std::filesystem;
using nlohmann::json;

void halves_to_floats(const uint16_t* in, float* out, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    Imath::half h;
    h.setBits(in[i]);
    out[i] = float(h);
  }
}
void floats_to_halves(const float* in, uint16_t* out, size_t n) {
  for (size_t i = 0; i < n; ++i) out[i] = Imath::half(in[i]).bits();
}

DirectionTable make_direction_table(const Sequence& seq, int width, int height, const BucketDesc& desc,
                                    int64_t probe_count) {
  sphere::Mapping m(seq.mapping, width, height, seq.dead_angle_deg);
  int n = desc.octahedral;
  if (n < 0 || n > 4096) fail(ErrorKind::Value, "direction buckets: octahedral resolution {} outside [0, 4096]", n);
  sphere::Mapping oct(sphere::MappingKind::Octahedral, std::max(n, 1), std::max(n, 1));
  struct Slot {
    int64_t bucket;
    int32_t pixel;
    Vec3 d;
    double w;
    Vec3 s;
  };
  std::vector<Slot> slots;
  bool ball = seq.mapping == sphere::MappingKind::MirrorBall && (seq.ball.radius > 0 || seq.ball.distance > 0);
  bool perspective = ball && seq.ball.distance > seq.ball.radius && seq.ball.radius > 0;
  double cos_dead = seq.dead_angle_deg > 0 ? std::cos(seq.dead_angle_deg * kPi / 180) : 2.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Vec3 d, s{0, 0, 0};
      double w;
      if (perspective) {
        if (!ball_ray(seq.ball, width, height, x + 0.5, y + 0.5, &s, &d) || d.z < -cos_dead) continue;
        w = ball_pixel_solid_angle(seq.ball, width, height, x, y);
      } else {
        if (!m.to_direction(x + 0.5, y + 0.5, &d)) continue;
        if (ball) ball_ray(seq.ball, width, height, x + 0.5, y + 0.5, &s, &d);  // the same direction, and the start
        w = m.solid_angle(x, y);
      }
      if (!(w > 0)) continue;
      d = normalize(seq.rotation * d);
      s = seq.rotation * s;
      int64_t b = int64_t(y) * width + x;
      if (n > 0) {
        double px, py;
        oct.to_pixel(d, &px, &py);
        b = std::clamp(int(py), 0, n - 1) * int64_t(n) + std::clamp(int(px), 0, n - 1);
      }
      slots.push_back({b, int32_t(int64_t(y) * width + x), d, w, s});
    }
  if (slots.empty())
    fail(ErrorKind::Value, "{}: frames of {}x{} in mapping {} carry no directions", seq.manifest, width, height,
         sphere::mapping_name(seq.mapping));
  std::stable_sort(slots.begin(), slots.end(), [](const Slot& a, const Slot& b) { return a.bucket < b.bucket; });
  DirectionTable t;
  t.width = width;
  t.height = height;
  t.pixel.reserve(slots.size());
  for (size_t i = 0; i < slots.size(); ++i) {
    if (i == 0 || slots[i].bucket != slots[i - 1].bucket) t.bucket_begin.push_back(int64_t(i));
    t.pixel.push_back(slots[i].pixel);
    t.dir.insert(t.dir.end(), {float(slots[i].d.x), float(slots[i].d.y), float(slots[i].d.z)});
    t.weight.push_back(slots[i].w);
    if (ball) t.start.insert(t.start.end(), {float(slots[i].s.x), float(slots[i].s.y), float(slots[i].s.z)});
  }
  t.bucket_begin.push_back(int64_t(slots.size()));
  // Blocks: at most max_block_buckets buckets and at most 1/8 of the memory budget of samples.
  size_t block_bytes_cap = std::max<size_t>(desc.memory_bytes / 8, 1 << 20);
  t.block_begin.push_back(0);
  int64_t in_block = 0;
  for (int b = 0; b < t.buckets(); ++b) {
    int64_t nb = t.bucket_begin[b + 1] - t.bucket_begin[b];
    bool full = b - t.block_begin.back() >= desc.max_block_buckets ||
                (in_block > 0 && size_t(in_block + nb) * probe_count * 6 > block_bytes_cap);
    if (full) {
      t.block_begin.push_back(b);
      in_block = 0;
    }
    in_block += nb;
  }
  t.block_begin.push_back(t.buckets());
  return t;
}

std::string BucketStore::block_path(const std::string& dir, int k) {
  return (fs::path(dir) / fmt::format("block_{:05d}.bin", k)).string();
}

bool is_cache_file(const fs::path& p) {
  const std::string n = p.filename().string();
  if (n == "index.json") return true;
  return n.size() == 15 && n.rfind("block_", 0) == 0 && n.substr(11) == ".bin" &&
         std::all_of(n.begin() + 6, n.begin() + 11, [](char c) { return c >= '0' && c <= '9'; });
}

// FNV-1a over the inputs that determine the block files' contents.
std::string bucket_cache_key(const Sequence& seq, const BucketDesc& desc, int w, int h) {
  uint64_t hsh = 1469598103934665603ull;
  auto mix = [&](const std::string& s) {
    for (unsigned char c : s) {
      hsh ^= c;
      hsh *= 1099511628211ull;
    }
  };
  mix(fmt::format("v1 {} {} {} {} {} {} {} {} {}", sphere::mapping_name(seq.mapping), seq.dead_angle_deg, w, h,
                  desc.octahedral, desc.max_block_buckets, desc.memory_bytes, desc.skip_bad, desc.sanitize));
  if (seq.ball.radius > 0 || seq.ball.distance > 0) mix(fmt::format("ball {} {}", seq.ball.radius, seq.ball.distance));
  for (int a = 0; a < 3; ++a)
    mix(fmt::format("{} {} {}", seq.rotation.m[a][0], seq.rotation.m[a][1], seq.rotation.m[a][2]));
  for (const auto& p : seq.probes) {
    std::error_code ec;
    auto sz = fs::file_size(p.image, ec);
    auto mt = fs::last_write_time(p.image, ec).time_since_epoch().count();
    mix(fmt::format("{}|{}|{}", p.image, ec ? 0 : sz, ec ? 0 : mt));
  }
  return fmt::format("{:016x}-{}", hsh, seq.probes.size());
}

void sequence_frame_size(const Sequence& seq, bool skip_bad, int* width, int* height) {
  int w = 0, h = 0;
  for (size_t i = 0; i < seq.probes.size() && w == 0; ++i) {
    try {
      auto spec = io::read_image_spec(seq.probes[i].image);
      w = spec.width;
      h = spec.height;
    } catch (const Error& e) {
      if (!skip_bad) fail(e.kind(), "probe {}: field \"image\": {}", i, e.what());
    }
  }
  if (w == 0) fail(ErrorKind::Io, "{}: no probe frame could be read", seq.manifest);
  *width = w;
  *height = h;
}

std::string read_probe_samples(const Sequence& seq, int p, const DirectionTable& t, const BucketDesc& desc,
                               std::vector<float>& rgb) {
  const auto& pe = seq.probes[p];
  std::string bad;
  Image img;
  try {
    img = io::read_image(pe.image, {desc.sanitize, 3});
    if (img.width() != t.width || img.height() != t.height)
      bad = fmt::format("field \"image\": {} is {}x{}, the sequence's frames are {}x{}", pe.image, img.width(),
                        img.height(), t.width, t.height);
  } catch (const Error& e) {
    bad = fmt::format("field \"image\": {}", e.what());
  }
  rgb.assign(size_t(t.slots()) * 3, 0.0f);
  if (bad.empty()) {
    double sum = 0;
    for (int64_t s = 0; s < t.slots(); ++s) {
      const float* px = img.data() + size_t(t.pixel[s]) * img.channels();
      for (int ch = 0; ch < 3; ++ch) rgb[s * 3 + ch] = img.channels() >= 3 ? px[ch] : px[0];
      sum += rgb[s * 3] + rgb[s * 3 + 1] + rgb[s * 3 + 2];
    }
    if (!(sum > 0)) bad = fmt::format("field \"image\": {} is all black inside the mapping", pe.image);
  }
  if (bad.empty()) return "";
  std::fill(rgb.begin(), rgb.end(), 0.0f);
  return fmt::format("{}: probe {}: {}", seq.manifest, p, bad);
}

void scatter_probe_samples(const DirectionTable& t, const float* rgb, int pc, int i, uint16_t* chunk) {
  for (int b = 0; b < t.buckets(); ++b) {
    int64_t s0 = t.bucket_begin[b], nb = t.bucket_begin[b + 1] - s0;
    floats_to_halves(rgb + s0 * 3, chunk + (size_t(pc) * s0 + size_t(i) * nb) * 3, size_t(nb) * 3);
  }
}

void BucketStore::load_block(int k, std::vector<uint16_t>& buf) const {
  const auto& t = table_;
  int64_t s0 = t.bucket_begin[t.block_begin[k]], s1 = t.bucket_begin[t.block_begin[k + 1]];
  size_t n = size_t(s1 - s0) * probe_count_ * 3;
  buf.resize(n);
  std::string path = block_path(dir_, k);
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) fail(ErrorKind::Io, "{}: cannot open bucket block", path);
  size_t got = std::fread(buf.data(), 2, n, f);
  std::fclose(f);
  if (got != n) fail(ErrorKind::Format, "{}: bucket block truncated ({} of {} values)", path, got, n);
}

const uint16_t* BucketStore::samples(const std::vector<uint16_t>& buf, int k, int b, int p) const {
  const auto& t = table_;
  int64_t s0 = t.bucket_begin[t.block_begin[k]], s1 = t.bucket_begin[t.block_begin[k + 1]];
  int64_t c = p / chunk_, pc = std::min<int64_t>(chunk_, probe_count_ - c * chunk_);
  size_t seg = size_t(c) * chunk_ * size_t(s1 - s0) * 3;
  int64_t nb = t.bucket_begin[b + 1] - t.bucket_begin[b];
  return buf.data() + seg + size_t(pc) * size_t(t.bucket_begin[b] - s0) * 3 + size_t(p - c * chunk_) * nb * 3;
}

namespace {

// Writes n halves at byte offset `offset` of file `path` (which exists).
void write_at(const std::string& path, const uint16_t* data, size_t n, int64_t offset) {
  int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) fail(ErrorKind::Io, "{}: cannot open bucket block ({})", path, std::strerror(errno));
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

// The index of an earlier run, when it describes complete block files of this plan: its valid flags,
// skip count and reasons.
bool read_index(const fs::path& index, const std::string& key, const DirectionTable& t, const SortPlan& plan,
                int probes, std::vector<uint8_t>& valid, BucketReport& rep) {
  if (!fs::exists(index)) return false;
  try {
    std::ifstream in(index);
    json j = json::parse(in);
    bool ok = j.value("key", "") == key && j.value("chunk", 0) == plan.chunk &&
              j.value("first_block", 0) == plan.block_begin && j.value("end_block", t.blocks()) == plan.block_end;
    for (int k = plan.block_begin; ok && k < plan.block_end; ++k) {
      size_t expect = size_t(t.bucket_begin[t.block_begin[k + 1]] - t.bucket_begin[t.block_begin[k]]) * probes * 6;
      auto path = BucketStore::block_path(index.parent_path().string(), k);
      ok = fs::exists(path) && fs::file_size(path) == expect;
    }
    if (!ok) return false;
    valid = j["valid"].get<std::vector<uint8_t>>();
    rep.skipped = j.value("skipped", 0);
    rep.reasons = j.value("reasons", std::vector<std::string>{});
    return int(valid.size()) == probes;
  } catch (const std::exception&) {
    return false;  // an unreadable index means the files are rebuilt
  }
}

}  // namespace

BucketStore BucketStore::sort(const Sequence& seq, const BucketDesc& desc, const ProgressFn& progress,
                              BucketReport* report, Collective* team_in) {
  Collective& team = team_in ? *team_in : serial_collective();
  BucketReport local;
  BucketReport& rep = report ? *report : local;
  rep = {};
  BucketStore st;
  st.dir_ = desc.dir;
  st.probe_count_ = int(seq.probes.size());
  const int P = st.probe_count_;
  // The first frame with a readable header fixes the size (its pixels are checked with the others').
  int w = 0, h = 0;
  team.agree([&] {
    if (desc.dir.empty()) fail(ErrorKind::Value, "direction buckets: no folder given for the block files");
    ibl::make_output_folders(desc.dir);
    sequence_frame_size(seq, desc.skip_bad, &w, &h);
    st.table_ = make_direction_table(seq, w, h, desc, P);
  });
  const auto& t = st.table_;
  const SortPlan plan = team.plan_sort(t, P, desc.memory_bytes);
  st.chunk_ = plan.chunk;
  st.block_begin_ = plan.block_begin;
  st.block_end_ = plan.block_end;
  const std::string key = bucket_cache_key(seq, desc, w, h) + plan.key_suffix;
  const fs::path index = fs::path(desc.dir) / plan.index;
  // Reuse: every process's blocks of an identical earlier run are complete.
  std::vector<uint8_t> valid;
  bool mine_ok = desc.reuse && read_index(index, key, t, plan, P, valid, rep);
  if (team.all(mine_ok)) {
    st.valid_ = std::move(valid);
    rep.reused = true;
    ibl::report(progress, "sort", 1.0);
    return st;
  }
  rep = {};
  team.agree([&] {
    std::error_code ec;
    fs::remove(index, ec);
    for (int k = plan.block_begin; k < plan.block_end; ++k) {
      FILE* f = std::fopen(block_path(desc.dir, k).c_str(), "wb");
      if (!f) fail(ErrorKind::Io, "{}: cannot create bucket block", block_path(desc.dir, k));
      std::fclose(f);
    }
  });
  st.valid_.assign(size_t(P), 1);
  std::vector<std::pair<int, std::string>> skips;
  std::vector<uint16_t> chunk(size_t(plan.chunk) * t.slots() * 3);
  int64_t done_before = 0;
  // Block k's share of a chunk g of pcs probes, in segment layout over the slots from slot0 on, goes
  // to its offset in the block file: segments lie in chunk order.
  auto write = [&](int g, int pcs, const uint16_t* segment, int64_t slot0) {
    for (int k = plan.block_begin; k < plan.block_end; ++k) {
      int64_t s0k = t.bucket_begin[t.block_begin[k]], nk = t.bucket_begin[t.block_begin[k + 1]] - s0k;
      write_at(block_path(desc.dir, k), segment + size_t(pcs) * size_t(s0k - slot0) * 3, size_t(pcs) * nk * 3,
               int64_t(g) * plan.chunk * nk * 6);
      rep.bytes_written += int64_t(pcs) * nk * 6;
    }
  };
  for (int c = 0; c < plan.rounds; ++c) {
    // Read this process's chunk of the round.
    auto t0 = std::chrono::steady_clock::now();
    const int g = plan.chunk_of_round[c], pc = plan.chunk_probes(g, P), p0 = g < 0 ? 0 : g * plan.chunk;
    int bad_probe = -1;
    std::string bad_msg;
    std::mutex mu;
    std::atomic<int64_t> done{0};
    team.agree([&] {
      parallel_for(0, pc, [&](int64_t i) {
        int p = p0 + int(i);
        std::vector<float> rgb;
        std::string msg = read_probe_samples(seq, p, t, desc, rgb);
        if (!msg.empty()) {
          std::lock_guard lk(mu);
          if (!desc.skip_bad) {
            if (bad_probe < 0 || p < bad_probe) bad_probe = p, bad_msg = msg;
          } else {
            st.valid_[p] = 0;
            skips.push_back({p, msg});
          }
        }
        scatter_probe_samples(t, rgb.data(), pc, int(i), chunk.data());
        ibl::report(progress, "sort", 0.9 * double(done_before + ++done) / P);
      });
      if (bad_probe >= 0) fail(ErrorKind::Value, "{} (skip_bad skips such probes)", bad_msg);
    });
    rep.read_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Deliver every block's samples to the process that writes it, and write them there.
    std::string write_error;
    ErrorKind write_kind = ErrorKind::Io;
    team.exchange(plan, t, c, chunk.data(), pc, [&](int gs, int pcs, const uint16_t* segment, int64_t slot0) {
      if (!write_error.empty() || pcs == 0) return;
      try {
        write(gs, pcs, segment, slot0);
      } catch (const Error& e) {
        write_error = e.what();
        write_kind = e.kind();
      }
    });
    team.agree([&] {
      if (!write_error.empty()) throw Error(write_kind, write_error);
    });
    int64_t n = pc;
    team.sum(&n, 1);
    done_before += n;
  }
  // Frames skipped anywhere: every process learns them, in probe order.
  team.min(st.valid_.data(), P);
  std::sort(skips.begin(), skips.end());
  std::vector<std::string> mine;
  for (auto& s : skips) mine.push_back(s.second);
  rep.reasons = team.gather(mine);
  rep.skipped = int(rep.reasons.size());
  team.agree([&] {
    if (rep.skipped == P) fail(ErrorKind::Value, "{}: every probe was skipped", seq.manifest);
  });
  team.agree([&] {
    json j = {{"key", key},
              {"chunk", plan.chunk},
              {"valid", st.valid_},
              {"skipped", rep.skipped},
              {"reasons", rep.reasons},
              {"first_block", plan.block_begin},
              {"end_block", plan.block_end},
              {"width", w},
              {"height", h},
              {"buckets", t.buckets()},
              {"blocks", t.blocks()},
              {"ranks", team.size()}};
    write_json_file(index.string(), j, -1);
  });
  ibl::report(progress, "sort", 1.0);
  return st;
}

void remove_bucket_cache(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file(ec) && is_cache_file(e.path())) fs::remove(e.path(), ec);
  if (fs::is_empty(dir, ec)) fs::remove(dir, ec);
}

}  // namespace ibl::ilf
