// The probe loop with progress (bake/run/probe_loop.h): every probe once, progress reported only by the
// calling thread, rising, ending at the total, for any thread count.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "bake/run/probe_loop.h"

namespace gibake {
namespace {

TEST(ProbeLoop, EveryProbeOnceProgressFromTheCallerOnly) {
  for (int threads : {1, 2, 4}) {
    SCOPED_TRACE(threads);
    tbb::task_arena arena(threads);
    std::vector<int32_t> probes(1003);
    for (size_t i = 0; i < probes.size(); ++i) probes[i] = int32_t(probes.size() - 1 - i);  // any order
    std::vector<std::atomic<int>> visits(probes.size());
    for (auto& v : visits) v = 0;
    const std::thread::id caller = std::this_thread::get_id();
    std::vector<double> done;
    bool other_thread = false, wrong_stage = false, wrong_total = false;
    Context ctx;
    ctx.progress = [&](const std::string& stage, double d, double total) {
      other_thread = other_thread || std::this_thread::get_id() != caller;
      wrong_stage = wrong_stage || stage != "trace";
      wrong_total = wrong_total || total != double(probes.size());
      done.push_back(d);
    };
    for_probes_reporting(arena, probes, ctx, "trace", [&](int32_t p) {
      volatile double sink = 0;  // some work, so other threads take chunks too
      for (int k = 0; k < 2000; ++k) sink = sink + k;
      ++visits[size_t(p)];
    });
    for (size_t p = 0; p < visits.size(); ++p) ASSERT_EQ(visits[p].load(), 1) << "probe " << p;
    EXPECT_FALSE(other_thread);
    EXPECT_FALSE(wrong_stage);
    EXPECT_FALSE(wrong_total);
    ASSERT_FALSE(done.empty());
    EXPECT_EQ(done.back(), double(probes.size()));
    for (size_t k = 1; k < done.size(); ++k) EXPECT_GT(done[k], done[k - 1]);
    if (threads == 1) {
      EXPECT_GE(done.size(), 40u);  // the caller does all: about 50 reports
    }
  }
}

}  // namespace
}  // namespace gibake
