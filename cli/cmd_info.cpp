// Placeholder until the info command lands.
#include "cli/commands.h"

namespace gibake::cli {

void add_info_command(CLI::App& app, CliState& state) {
  CLI::App* sub = app.add_subcommand("info", "info (not yet implemented)");
  sub->allow_extras();
  sub->callback([&state] {
    state.run = [] {
      return report_error(Status::error(ExitCode::RuntimeFailure, "", "info", "not implemented yet"));
    };
  });
}

}  // namespace gibake::cli
