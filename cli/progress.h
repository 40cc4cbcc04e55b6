// Progress on stderr for long commands: a redrawn bar on a terminal, plain lines otherwise,
// JSON lines with --progress json. update() is thread-safe.
#pragma once
#include <chrono>
#include <memory>
#include <mutex>
#include <string>

#include "io/context.h"
#include "io/status.h"
#include "io/timer.h"

namespace gibake::cli {

enum class ProgressMode { Auto, Bar, Lines, Json };

// "auto", "bar", "lines", "json"; false for anything else.
bool parse_progress_mode(const std::string& text, ProgressMode& out);
// --progress: the same, a BadArguments Status naming the option and the value otherwise.
Status parse_progress_option(const std::string& text, ProgressMode& out);

class Progress {
 public:
  explicit Progress(ProgressMode mode);
  ~Progress();
  void update(const std::string& stage, double done, double total);
  // Ends a bar line (if one is drawn) before other output.
  void clear();
  // One free-form event: a line in bar/lines mode, {"event":..,"message":..} in JSON mode.
  void note(const std::string& event, const std::string& message);
  ProgressMode mode() const { return mode_; }

 private:
  ProgressMode mode_;
  std::mutex mutex_;
  std::string stage_;
  int last_percent_ = -1;
  int pass_ = 1;  // of stage_: 2 and up once it started over
  bool bar_open_ = false;
  Clock::time_point start_;
};

// A Context for a command that shows `progress`: stage updates go to it, and warnings end its bar
// line before they print.
Context progress_context(const std::shared_ptr<Progress>& progress, unsigned threads);

}  // namespace gibake::cli
