// Placeholder until the export command lands.
#include "cli/commands.h"

namespace gibake::cli {

void add_export_command(CLI::App& app, CliState& state) {
  CLI::App* sub = app.add_subcommand("export", "export (not yet implemented)");
  sub->allow_extras();
  sub->callback([&state] {
    state.run = [] {
      return report_error(Status::error(ExitCode::RuntimeFailure, "", "export", "not implemented yet"));
    };
  });
}

}  // namespace gibake::cli
