// The context every library entry point takes instead of global state.
#pragma once
#include <functional>
#include <string>

namespace gibake {

// Progress of a long stage: stage name, items done, items total (0 when unknown).
using ProgressFn = std::function<void(const std::string& stage, double done, double total)>;
using WarningFn = std::function<void(const std::string& message)>;

struct Context {
  unsigned threads = 0;  // 0: all hardware threads
  WarningFn warn;        // optional; warnings are dropped when empty
  WarningFn info;        // optional; what a stage decided (e.g. the probe grid), for the user
  ProgressFn progress;   // optional

  void warning(const std::string& message) const {
    if (warn) warn(message);
  }
  void note(const std::string& message) const {
    if (info) info(message);
  }
  void report(const std::string& stage, double done, double total) const {
    if (progress) progress(stage, done, total);
  }
};

}  // namespace gibake
