// The TBB arena a stage runs in: --threads workers, or TBB's default when 0.
#pragma once
#include <tbb/info.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

#include "io/context.h"
#include "io/timer.h"

namespace gibake {

inline std::unique_ptr<tbb::task_arena> make_arena(const Context& ctx) {
  return ctx.threads > 0 ? std::make_unique<tbb::task_arena>(static_cast<int>(ctx.threads))
                         : std::make_unique<tbb::task_arena>();
}

// The threads a stage's arena runs on.
inline uint32_t worker_count(const Context& ctx) {
  return ctx.threads > 0 ? uint32_t(ctx.threads) : uint32_t(std::max(1, tbb::info::default_concurrency()));
}

// One task that runs in an arena beside the stages that follow and is waited for later (so
// --threads still bounds everything). wait() rethrows the task's exception; the destructor waits
// too, so an early return never leaves the task running on data that is gone.
class BesideTask {
 public:
  BesideTask() = default;
  BesideTask(const BesideTask&) = delete;
  BesideTask& operator=(const BesideTask&) = delete;
  ~BesideTask() {
    try {
      wait();
    } catch (...) {
    }
  }

  void start(tbb::task_arena& arena, std::function<void()> fn) {
    arena_ = &arena;
    arena.execute([&] {
      group_.run([this, fn = std::move(fn)] {
        const Stopwatch task_time;
        try {
          fn();
        } catch (...) {
          error_ = std::current_exception();
        }
        seconds_ = task_time.seconds();
      });
    });
  }
  // Waits inside the arena (this thread helps with its work meanwhile). Returns the seconds spent
  // waiting; the task's own time is seconds().
  double wait() {
    if (!arena_) return 0.0;
    const Stopwatch wait_time;
    arena_->execute([&] { group_.wait(); });
    arena_ = nullptr;
    const double waited = wait_time.seconds();
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return waited;
  }
  double seconds() const { return seconds_; }
  bool started() const { return arena_ != nullptr; }

 private:
  tbb::task_arena* arena_ = nullptr;
  tbb::task_group group_;
  std::exception_ptr error_;
  double seconds_ = 0.0;
};

// Owners of what a stage is done with (unique_ptr, shared_ptr), destroyed on a thread of their own
// while the bake goes on: freeing gigabytes of device memory or a whole device takes tens of ms
// (docs/BENCHMARKS.md). One release at a time, in order: each release's thread first joins the one
// before (the caller never waits for an earlier release); wait() (from any thread) and the
// destructor join the last, hence all. What is released must be idle (its device work waited for).
// The thread is outside any arena: it spends its time in the driver, not on --threads' work.
class ReleaseBeside {
 public:
  ReleaseBeside() = default;
  ReleaseBeside(const ReleaseBeside&) = delete;
  ReleaseBeside& operator=(const ReleaseBeside&) = delete;
  ~ReleaseBeside() { wait(); }
  template <class... Owner>
  void release(Owner... owners) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::thread before = std::move(thread_);
    thread_ = std::thread(
        [](std::thread earlier, Owner... o) {
          if (earlier.joinable()) earlier.join();
          (o.reset(), ...);
        },
        std::move(before), std::move(owners)...);
  }
  // Before memory the released objects held is wanted again.
  void wait() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::mutex mutex_;
  std::thread thread_;
};

}  // namespace gibake
