// Placeholder until the inspect command lands.
#include "cli/commands.h"

namespace gibake::cli {

void add_inspect_command(CLI::App& app, CliState& state) {
  CLI::App* sub = app.add_subcommand("inspect", "inspect (not yet implemented)");
  sub->allow_extras();
  sub->callback([&state] {
    state.run = [] {
      return report_error(Status::error(ExitCode::RuntimeFailure, "", "inspect", "not implemented yet"));
    };
  });
}

}  // namespace gibake::cli
