// Placeholder until the verify command lands.
#include "cli/commands.h"

namespace gibake::cli {

void add_verify_command(CLI::App& app, CliState& state) {
  CLI::App* sub = app.add_subcommand("verify", "verify (not yet implemented)");
  sub->allow_extras();
  sub->callback([&state] {
    state.run = [] {
      return report_error(Status::error(ExitCode::RuntimeFailure, "", "verify", "not implemented yet"));
    };
  });
}

}  // namespace gibake::cli
