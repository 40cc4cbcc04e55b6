// Parallel loops over probes on the bake's arena. Every probe writes only its own slots, so the
// results do not depend on scheduling or thread count.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
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

// The same, reporting progress for `stage` from the calling thread (which joins the arena's work)
// about 50 times. One loop over all probes: no barrier between parts, so a slow probe holds back
// nothing but its own chunk (waves with a barrier left most of 16 threads idle at each wave's end).
template <class F>
void for_probes_reporting(tbb::task_arena& arena, const std::vector<int32_t>& probes, const Context& ctx,
                          const std::string& stage, F&& f) {
  const size_t total = probes.size();
  const size_t step = std::max<size_t>(1, total / 50);
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<size_t> done{0};
  size_t reported = 0;  // read and written by the calling thread only
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, total, 2),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i != r.end(); ++i) f(probes[i]);
          const size_t now = done.fetch_add(r.size(), std::memory_order_relaxed) + r.size();
          if (std::this_thread::get_id() == caller && now >= reported + step && now < total) {
            reported = now;
            ctx.report(stage, static_cast<double>(now), static_cast<double>(total));
          }
        },
        tbb::simple_partitioner());
  });
  ctx.report(stage, static_cast<double>(total), static_cast<double>(total));
}

}  // namespace gibake
