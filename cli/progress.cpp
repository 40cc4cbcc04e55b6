#include "cli/progress.h"
#include "io/timer.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace gibake::cli {

bool parse_progress_mode(const std::string& text, ProgressMode& out) {
  if (text == "auto") out = ProgressMode::Auto;
  else if (text == "bar") out = ProgressMode::Bar;
  else if (text == "lines") out = ProgressMode::Lines;
  else if (text == "json") out = ProgressMode::Json;
  else return false;
  return true;
}

Progress::Progress(ProgressMode mode) : mode_(mode), start_(Clock::now()) {
  if (mode_ == ProgressMode::Auto) mode_ = isatty(STDERR_FILENO) ? ProgressMode::Bar : ProgressMode::Lines;
}

Progress::~Progress() { clear(); }

void Progress::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (bar_open_) {
    std::fputc('\n', stderr);
    bar_open_ = false;
  }
}

void Progress::update(const std::string& stage, double done, double total) {
  std::lock_guard<std::mutex> lock(mutex_);
  const int percent = total > 0 ? static_cast<int>(std::floor(100.0 * done / total)) : -1;
  const bool new_stage = stage != stage_;
  const double elapsed = seconds_since(start_);
  switch (mode_) {
    case ProgressMode::Bar: {
      if (!new_stage && percent == last_percent_) return;
      if (new_stage && bar_open_) std::fputc('\n', stderr);
      const int width = 30, fill = percent < 0 ? 0 : percent * width / 100;
      std::fprintf(stderr, "\r%-12s [%.*s%*s] %3d%%  %6.1fs", stage.c_str(), fill,
                   "##############################", width - fill, "", percent < 0 ? 0 : percent, elapsed);
      std::fflush(stderr);
      bar_open_ = true;
      break;
    }
    case ProgressMode::Lines:
      // One line per stage start, then every 25%.
      if (!new_stage && (percent < 0 || percent / 25 == last_percent_ / 25)) return;
      std::fprintf(stderr, "gibake: %s %d%% (%.1fs)\n", stage.c_str(), percent < 0 ? 0 : percent, elapsed);
      break;
    case ProgressMode::Json:
    case ProgressMode::Auto: {
      if (!new_stage && percent == last_percent_) return;
      nlohmann::json j{{"event", "progress"}, {"stage", stage}, {"done", done}, {"total", total}, {"elapsed_s", elapsed}};
      std::fprintf(stderr, "%s\n", j.dump().c_str());
      break;
    }
  }
  stage_ = stage;
  last_percent_ = percent;
}

void Progress::note(const std::string& event, const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (bar_open_) {
    std::fputc('\n', stderr);
    bar_open_ = false;
  }
  if (mode_ == ProgressMode::Json) {
    std::fprintf(stderr, "%s\n", nlohmann::json{{"event", event}, {"message", message}}.dump().c_str());
  } else {
    std::fprintf(stderr, "%s\n", message.c_str());
  }
}

}  // namespace gibake::cli
