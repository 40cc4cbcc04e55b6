// Subcommand registration: each cmd_*.cpp turns its argv into a config struct and, when its
// subcommand is chosen, sets `run` to a closure that calls the library and returns an exit code.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <iostream>

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

void add_bake_command(CLI::App& app, CliState& state);
void add_inspect_command(CLI::App& app, CliState& state);
void add_info_command(CLI::App& app, CliState& state);
void add_verify_command(CLI::App& app, CliState& state);
void add_export_command(CLI::App& app, CliState& state);
void add_preview_command(CLI::App& app, CliState& state);
void add_merge_command(CLI::App& app, CliState& state);
void add_sample_command(CLI::App& app, CliState& state);

}  // namespace gibake::cli
