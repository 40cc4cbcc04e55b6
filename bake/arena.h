// The TBB arena a stage runs in: --threads workers, or TBB's default when 0.
#pragma once
#include <tbb/task_arena.h>

#include <memory>

#include "io/context.h"

namespace gibake {

inline std::unique_ptr<tbb::task_arena> make_arena(const Context& ctx) {
  return ctx.threads > 0 ? std::make_unique<tbb::task_arena>(static_cast<int>(ctx.threads))
                         : std::make_unique<tbb::task_arena>();
}

}  // namespace gibake
