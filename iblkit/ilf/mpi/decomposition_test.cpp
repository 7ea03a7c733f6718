// The split of the distributed ILF build (ilf/mpi/decomposition.h): every sample slot has exactly one
// owner, every probe exactly one reader, the schedule fits every rank in the same number of rounds.
#include <gtest/gtest.h>

#include "iblkit/ilf/mpi/decomposition.h"

namespace ibl::ilf::mpi {
namespace {

// A table of `buckets` buckets of `per` slots each in blocks of `per_block` buckets.
DirectionTable table(int buckets, int per, int per_block) {
  DirectionTable t;
  for (int b = 0; b <= buckets; ++b) t.bucket_begin.push_back(int64_t(b) * per);
  t.pixel.assign(size_t(buckets) * per, 0);
  for (int b = 0; b < buckets; b += per_block) t.block_begin.push_back(b);
  t.block_begin.push_back(buckets);
  return t;
}

TEST(IlfMpiDecomposition, EverySlotOneOwnerEveryProbeOneReader) {
  for (int ranks : {1, 2, 3, 4, 7, 16}) {
    for (int probes : {1, 2, 5, 61, 4397}) {
      auto t = table(49, 3, 4);  // 13 blocks, the last one short
      auto d = decompose(t, probes, ranks, size_t(64) << 20);
      ASSERT_EQ(int(d.block_begin.size()), ranks + 1);
      EXPECT_EQ(d.block_begin.front(), 0);
      EXPECT_EQ(d.block_begin.back(), t.blocks());
      for (int q = 0; q < ranks; ++q) EXPECT_LE(d.block_begin[q], d.block_begin[q + 1]);
      EXPECT_EQ(d.slot_begin.back(), t.slots());
      std::vector<int> read(size_t(probes), 0);
      for (int r = 0; r < ranks; ++r)
        for (int c = 0; c < d.rounds; ++c) {
          int g = d.chunk_of(r, c);
          for (int i = 0; i < d.chunk_probes(g); ++i) ++read[size_t(g) * d.chunk + i];
        }
      for (int p = 0; p < probes; ++p)
        EXPECT_EQ(read[p], 1) << "probe " << p << " of " << probes << ", " << ranks << " ranks";
      // Balance: no rank reads more than one chunk more than another, and a rank's chunk is at most
      // its share of the probes.
      EXPECT_LE(d.chunk, (probes + ranks - 1) / ranks);
      for (int r = 0; r < ranks; ++r) EXPECT_LE(d.chunk_begin[r + 1] - d.chunk_begin[r], d.rounds);
    }
  }
}

TEST(IlfMpiDecomposition, BlocksBalancedBySlotsAndChunksByMemory) {
  auto t = table(1000, 5, 10);  // 100 blocks of 50 slots
  auto d = decompose(t, 4397, 4, size_t(64) << 20);
  for (int q = 0; q < 4; ++q) EXPECT_EQ(d.blocks_of(q), 25);
  // One round's send buffer (chunk × slots × 3 halves) within an eighth of the budget.
  auto big = table(49024, 1, 64);  // the paper's 250² balls: 49 024 pixel buckets
  auto e = decompose(big, 4397, 2, size_t(2) << 30);
  EXPECT_LE(size_t(e.chunk) * big.slots() * 6, (size_t(2) << 30) / 8);
  EXPECT_GT(e.rounds, 1);
  EXPECT_EQ(e.chunk, int((size_t(2) << 30) / 8 / (size_t(big.slots()) * 6)));
}

}  // namespace
}  // namespace ibl::ilf::mpi
