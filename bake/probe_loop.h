// Parallel loops over probes on the bake's arena. Every probe writes only its own slots, so the
// results do not depend on scheduling or thread count.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "io/context.h"

namespace gibake {

// Runs f(probe) for every listed probe on the arena, in fixed chunks of 2.
template <class F>
void for_probes(tbb::task_arena& arena, const std::vector<int32_t>& probes, F&& f) {
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, probes.size(), 2),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i != r.end(); ++i) f(probes[i]);
        },
        tbb::simple_partitioner());
  });
}

// The same in waves, reporting progress for `stage` from the calling thread between them.
template <class F>
void for_probes_waves(tbb::task_arena& arena, const std::vector<int32_t>& probes, const Context& ctx,
                      const std::string& stage, F&& f) {
  const size_t wave = std::max<size_t>(64, probes.size() / 50);
  for (size_t start = 0; start < probes.size(); start += wave) {
    std::vector<int32_t> part(probes.begin() + start, probes.begin() + std::min(probes.size(), start + wave));
    for_probes(arena, part, f);
    ctx.report(stage, static_cast<double>(std::min(probes.size(), start + wave)), static_cast<double>(probes.size()));
  }
}

}  // namespace gibake
