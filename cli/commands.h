// Subcommand registration: each cmd_*.cpp defines one Command, which gives its subcommand its help
// and options (filling an args struct) and, when the subcommand is the one chosen, sets `run` to a
// closure that calls the library and returns an exit code. main.cpp lists the commands.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <iostream>
#include <memory>

#include "io/context.h"
#include "io/status.h"

namespace gibake::cli {

struct CliState {
  std::function<int()> run;  // set by the chosen subcommand's callback
};

// Prints "gibake: error: <file>: <where>: <what>" and returns the exit code.
inline int report_error(const Status& status) {
  std::cerr << "gibake: error: " << status.message() << "\n";
  return static_cast<int>(status.code());
}
inline void print_warning(const std::string& message) {
  std::cerr << "gibake: warning: " << message << "\n";
}

struct Command {
  const char* name;
  void (*add)(CLI::App& sub, CliState& state);  // help, options and the callback that sets state.run
};

// `add` for the usual command: Options gives `sub` its description and options over a fresh Args;
// once argv is parsed, state.run calls Run with them.
template <class Args, void (*Options)(CLI::App&, Args&), int (*Run)(const Args&)>
void add_command(CLI::App& sub, CliState& state) {
  auto args = std::make_shared<Args>();
  Options(sub, *args);
  sub.callback([&state, args] { state.run = [args] { return Run(*args); }; });
}

// One a cmd_*.cpp; main.cpp lists them.
extern const Command kBakeCommand, kInspectCommand, kInfoCommand, kVerifyCommand, kExportCommand, kPreviewCommand,
    kMergeCommand, kSampleCommand;

}  // namespace gibake::cli
