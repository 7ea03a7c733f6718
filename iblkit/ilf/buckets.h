// Step 2 of `ilf build`: sorting the radiance samples of a probe sequence into direction buckets,
// out of core ([1] §3 "Sorting"). Each frame is read once; its samples are written as half floats into
// block files grouped by direction, so that the later stages stream one block of directions at a
// time and peak memory stays under a budget whatever the number of probes.
//
// A bucket is either one probe pixel (the paper's buckets: every probe contributes exactly one ray per
// bucket, all rays parallel) or one cell of an n×n octahedral partition of the sphere (several pixels
// per probe, rays within a few degrees of each other). File layout, per block file `block_XXXXX.bin`:
// one segment per probe chunk, in chunk order; within a segment, for each bucket of the block, for each
// probe of the chunk, the bucket's samples as RGB half floats.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "iblkit/core/progress.h"
#include "iblkit/ilf/sequence.h"

namespace ibl::ilf {

class Collective;  // collective.h

struct BucketDesc {
  std::string dir;                        // folder for the block files and index.json (created if missing)
  int octahedral = 0;                     // 0: one bucket per probe pixel; n > 0: n×n octahedral direction cells
  int max_block_buckets = 64;             // most buckets in one block (the unit later stages process at once)
  size_t memory_bytes = size_t(2) << 30;  // peak memory budget of the whole build, bytes
  bool skip_bad = false;                  // frames that fail (unreadable, wrong size, NaN/Inf, all black) are skipped
  bool sanitize = false;                  // replace NaN/Inf/negative pixels by 0 instead of failing
  bool reuse = true;                      // reuse the block files of an identical earlier run
};

// Which probe pixels feed which bucket, their world directions and exact solid angles.
struct DirectionTable {
  int width = 0, height = 0;          // frame size every probe must have
  std::vector<int32_t> pixel;         // per sample slot: pixel index y·width + x, ordered by bucket
  std::vector<float> dir;             // per sample slot: world direction, 3 floats
  std::vector<double> weight;         // per sample slot: exact solid angle of the pixel (sr)
  std::vector<float> start;           // per sample slot: world offset of the ray's start from the probe
                                      // position (its reflection point on the ball), 3 floats; empty for a
                                      // single viewpoint (Sequence::ball.radius 0)
  std::vector<int64_t> bucket_begin;  // bucket b owns slots [bucket_begin[b], bucket_begin[b+1])
  std::vector<int> block_begin;       // block k owns buckets [block_begin[k], block_begin[k+1])
  int buckets() const { return int(bucket_begin.size()) - 1; }
  int blocks() const { return int(block_begin.size()) - 1; }
  int64_t slots() const { return int64_t(pixel.size()); }
};

// Builds the table for a frame size. Pixels whose centre has no direction (outside the mirror ball's
// disc, in its dead angle, unused cube-cross cells) get no slot. A mirror ball with a radius gives each
// slot its start on the ball (ilf/ball.h), with a camera distance also its perspective direction and
// solid angle.
DirectionTable make_direction_table(const Sequence& seq, int width, int height, const BucketDesc& desc,
                                    int64_t probe_count);

struct BucketReport {
  int skipped = 0;                   // frames skipped (skip_bad)
  std::vector<std::string> reasons;  // one line per skipped frame
  bool reused = false;               // block files of an earlier identical run were reused
  double read_seconds = 0;           // time spent decoding frames
  int64_t bytes_written = 0;         // size of the block files
};

// The sorted samples on disk.
class BucketStore {
 public:
  const DirectionTable& table() const { return table_; }
  int probe_count() const { return probe_count_; }
  // The blocks this process holds: all of them, or its share of a sort split between processes.
  int block_begin() const { return block_begin_; }
  int block_end() const { return block_end_; }
  // valid[p]: probe p's frame was read (false: skipped; its samples are zeros and must be ignored).
  const std::vector<uint8_t>& valid() const { return valid_; }
  // Reads block k into buf (half floats).
  void load_block(int k, std::vector<uint16_t>& buf) const;
  // In a buffer filled by load_block(k, buf): the 3·n_b halfs of bucket b (which must lie in block k)
  // for probe p.
  const uint16_t* samples(const std::vector<uint16_t>& buf, int k, int b, int p) const;

  // Sorts every frame of seq into the block files of desc.dir (reusing those of an identical earlier
  // run). Split between the processes of a job by `team` (collective.h; none: this process alone):
  // each writes and then holds its share of the blocks (Collective::plan_sort), and every process
  // gets the same valid flags and skip reasons.
  static BucketStore sort(const Sequence& seq, const BucketDesc& desc, const ProgressFn& progress = {},
                          BucketReport* report = nullptr, Collective* team = nullptr);
  // The file of block k in folder dir.
  static std::string block_path(const std::string& dir, int k);

 private:
  std::string dir_;
  DirectionTable table_;
  int probe_count_ = 0, chunk_ = 0;
  int block_begin_ = 0, block_end_ = 0;
  std::vector<uint8_t> valid_;
};

// The frame size every probe must have: the first probe whose header reads. Throws the sort's error
// when that fails for a probe and skip_bad is off, or when no header reads.
void sequence_frame_size(const Sequence& seq, bool skip_bad, int* width, int* height);
// Reads probe p's frame into rgb (3 floats per slot of t). Returns "" for a good frame, else the line
// the sort fails with or reports ("MANIFEST: probe P: field \"image\": …"); rgb is then zeros.
std::string read_probe_samples(const Sequence& seq, int p, const DirectionTable& t, const BucketDesc& desc,
                               std::vector<float>& rgb);
// Writes probe i's rgb as halves into a chunk buffer of pc probes laid out as a block file's segment:
// bucket b's region starts at pc·bucket_begin[b]·3 and holds [probe in chunk][sample][rgb].
void scatter_probe_samples(const DirectionTable& t, const float* rgb, int pc, int i, uint16_t* chunk);
// The key of index.json: the frames (path, size, modification time), mapping and settings.
std::string bucket_cache_key(const Sequence& seq, const BucketDesc& desc, int width, int height);

// Removes the bucket cache a sort wrote into `dir` (its block_NNNNN.bin files and index.json), and
// `dir` itself once nothing else is in it; what else is there stays. Nothing to remove is no error.
void remove_bucket_cache(const std::string& dir);

// Half-float conversion helpers (IEEE binary16).
void halves_to_floats(const uint16_t* in, float* out, size_t n);
void floats_to_halves(const float* in, uint16_t* out, size_t n);

}  // namespace ibl::ilf
