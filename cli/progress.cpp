#include "cli/progress.h"
#include "io/timer.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli/commands.h"

namespace gibake::cli {

bool parse_progress_mode(const std::string& text, ProgressMode& out) {
  if (text == "auto") out = ProgressMode::Auto;
  else if (text == "bar") out = ProgressMode::Bar;
  else if (text == "lines") out = ProgressMode::Lines;
  else if (text == "json") out = ProgressMode::Json;
  else return false;
  return true;
}

Status parse_progress_option(const std::string& text, ProgressMode& out) {
  if (parse_progress_mode(text, out)) return Status::ok();
  return Status::error(ExitCode::BadArguments, "", "--progress", "expected auto, bar, lines or json, got '" + text + "'");
}

namespace {
// What a stage that runs again is running again for: LPV propagation runs once per cascade; the
// others (relocation, the adaptive trace) make passes, the word the docs use.
const char* repeat_word(const std::string& stage) {
  if (stage.rfind("lpv", 0) == 0) return "cascade";
  return "pass";
}
}  // namespace

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

void Progress::update(const std::string& stage_name, double done, double total) {
  std::lock_guard<std::mutex> lock(mutex_);
  const int percent = total > 0 ? static_cast<int>(std::floor(100.0 * done / total)) : -1;
  // A stage that starts over right after finishing (relocation runs two passes) is its next pass.
  bool new_stage = stage_name != stage_;
  if (new_stage) pass_ = 1;
  else if (percent >= 0 && percent < last_percent_ && last_percent_ == 100) {
    ++pass_;
    new_stage = true;
  }
  const std::string stage = pass_ > 1 ? stage_name + " (" + repeat_word(stage_name) + " " + std::to_string(pass_) + ")"
                                      : stage_name;
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
      nlohmann::json j{{"event", "progress"}, {"stage", stage_name}, {"done", done}, {"total", total}, {"elapsed_s", elapsed}};
      if (pass_ > 1) j["pass"] = pass_;
      std::fprintf(stderr, "%s\n", j.dump().c_str());
      break;
    }
  }
  stage_ = stage_name;
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

Context progress_context(const std::shared_ptr<Progress>& progress, unsigned threads) {
  Context ctx;
  ctx.threads = threads;
  ctx.warn = [progress](const std::string& m) {
    progress->clear();
    print_warning(m);
  };
  ctx.progress = [progress](const std::string& stage, double done, double total) {
    progress->update(stage, done, total);
  };
  return ctx;
}

}  // namespace gibake::cli
