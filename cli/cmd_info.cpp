// gibake info probes.bin [--probes] [--format text|json]: what a bake file holds.
#include <string>

#include "cli/commands.h"
#include "io/bakefile/bake_info.h"

namespace gibake::cli {

namespace {
struct InfoConfig {
  std::string path;
  bool probes = false;
  std::string format = "text";
};
}  // namespace

void add_info_command(CLI::App& app, CliState& state) {
  auto config = std::make_shared<InfoConfig>();
  CLI::App* sub = app.add_subcommand("info", "Show what a bake file holds (sections, metadata, volumes)");
  sub->add_option("file", config->path, "Bake file")->required();
  sub->add_flag("--probes", config->probes, "List every probe (coordinate, position, state, SH)");
  sub->add_option("--format", config->format, "Output format")->check(CLI::IsMember({"text", "json"}));
  sub->callback([&state, config] {
    state.run = [config] {
      InfoOptions options;
      options.probes = config->probes;
      options.json = config->format == "json";
      const Status status = bake_info(config->path, options, std::cout);
      return status ? 0 : report_error(status);
    };
  });
}

}  // namespace gibake::cli
