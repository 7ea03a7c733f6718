#include "iblkit/ilf/collective.h"

#include <algorithm>

namespace ibl::ilf {

SortPlan Collective::plan_sort(const DirectionTable& t, int probes, size_t memory_bytes) {
  // One buffer of chunk probes' samples within a quarter of the memory budget.
  SortPlan plan;
  size_t per_probe = size_t(std::max<int64_t>(t.slots(), 1)) * 3 * 2;
  plan.chunk = int(std::clamp<size_t>(memory_bytes / 4 / per_probe, 1, size_t(std::max(probes, 1))));
  plan.rounds = (probes + plan.chunk - 1) / plan.chunk;
  plan.block_begin = 0;
  plan.block_end = t.blocks();
  for (int c = 0; c < plan.rounds; ++c) plan.chunk_of_round.push_back(c);
  return plan;
}

void Collective::exchange(const SortPlan& plan, const DirectionTable& t, int round, const uint16_t* chunk, int pc,
                          const std::function<void(int, int, const uint16_t*, int64_t)>& write) {
  write(plan.chunk_of_round[round], pc, chunk, 0);
}

Collective& serial_collective() {
  static Collective one;
  return one;
}

std::vector<int> split_evenly(int n, int size) {
  std::vector<int> begin(size_t(size) + 1);
  for (int r = 0; r <= size; ++r) begin[r] = int(int64_t(n) * r / size);
  return begin;
}

}  // namespace ibl::ilf
