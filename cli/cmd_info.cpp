// gibake info probes.bin [--probes] [--format text|json]: what a bake file holds.
// gibake info --devices [--format text|json]: the Vulkan devices --backend can use.
#include <string>

#include "bake/run/backend.h"
#include "cli/commands.h"
#include "io/bakefile/bake_info.h"

namespace gibake::cli {

namespace {
struct InfoArgs {
  std::string path;
  bool probes = false;
  bool devices = false;
  std::string format = "text";
};
}  // namespace

void add_info_command(CLI::App& app, CliState& state) {
  auto config = std::make_shared<InfoArgs>();
  CLI::App* sub = app.add_subcommand("info", "Show what a bake file holds (sections, metadata, volumes)");
  sub->add_option("file", config->path, "Bake file");
  sub->add_flag("--devices", config->devices, "List the Vulkan devices (for --backend / --vulkan-device)");
  sub->add_flag("--probes", config->probes, "List every probe (coordinate, position, state, SH)");
  sub->add_option("--format", config->format, "Output format")->check(CLI::IsMember({"text", "json"}));
  sub->callback([&state, config] {
    state.run = [config] {
      if (config->devices) {
        if (!config->path.empty()) return report_error(Status::error(ExitCode::BadArguments, "", "--devices", "takes no file"));
        const Status status = write_device_list(config->format == "json", std::cout);
        return status ? 0 : report_error(status);
      }
      if (config->path.empty())
        return report_error(Status::error(ExitCode::BadArguments, "", "info", "a bake file (or --devices) is required"));
      InfoOptions options;
      options.probes = config->probes;
      options.json = config->format == "json";
      const Status status = bake_info(config->path, options, std::cout);
      return status ? 0 : report_error(status);
    };
  });
}

}  // namespace gibake::cli
