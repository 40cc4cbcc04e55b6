// The one stage timer of the code base: wall-clock seconds on the steady clock, for the timings
// that summaries, reports and metadata print.
#pragma once
#include <chrono>

namespace gibake {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

inline double seconds_between(Clock::time_point t0, Clock::time_point t1) {
  return std::chrono::duration<double>(t1 - t0).count();
}

// Seconds since construction or the last restart(); lap() returns them and restarts.
class Stopwatch {
 public:
  double seconds() const { return seconds_since(start_); }
  double lap() {
    const Clock::time_point now = Clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return s;
  }
  void restart() { start_ = Clock::now(); }

 private:
  Clock::time_point start_ = Clock::now();
};

}  // namespace gibake
