// Placeholder until the bake command lands.
#include "cli/commands.h"

namespace gibake::cli {

void add_bake_command(CLI::App& app, CliState& state) {
  CLI::App* sub = app.add_subcommand("bake", "bake (not yet implemented)");
  sub->allow_extras();
  sub->callback([&state] {
    state.run = [] {
      return report_error(Status::error(ExitCode::RuntimeFailure, "", "bake", "not implemented yet"));
    };
  });
}

}  // namespace gibake::cli
