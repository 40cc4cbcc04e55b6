// gibake info probes.gibake [--probes] [--format text|json]: what a bake file holds.
// gibake info --devices [--format text|json]: the Vulkan devices --backend can use.
#include <string>

#include "bake/run/backend.h"
#include "cli/commands.h"
#include "cli/help.h"
#include "io/bakefile/bake_info.h"

namespace gibake::cli {

namespace {
struct InfoArgs {
  std::string path;
  bool probes = false;
  bool devices = false;
  std::string format = "text";
};

void info_options(CLI::App& sub, InfoArgs& a) {
  sub.description("Show what a bake file holds, or list the Vulkan devices");
  sub.footer("Prints the volumes and cascades, the sections and the metadata of FILE (numbers rounded in text).\n"
             "Every option at length: docs/cli/info.md");
  sub.add_option("FILE", a.path, "a bake file (none with --devices)")->group("Input and output");
  OptionGroup g(sub, "Input and output");
  g.flag("--probes", a.probes, "list every probe: coordinate, position, state, SH");
  g.flag("--devices", a.devices, "list the Vulkan devices (for --backend, --vulkan-device)");
  g.option("--format", a.format, "text|json", "output format on stdout")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
}

int run_info(const InfoArgs& a) {
  if (a.devices) {
    if (!a.path.empty()) return report_error(Status::error(ExitCode::BadArguments, "", "--devices", "takes no file"));
    const Status status = write_device_list(a.format == "json", std::cout);
    return status ? 0 : report_error(status);
  }
  if (a.path.empty())
    return report_error(Status::error(ExitCode::BadArguments, "", "info", "a bake file (or --devices) is required"));
  InfoOptions options;
  options.probes = a.probes;
  options.json = a.format == "json";
  const Status status = bake_info(a.path, options, std::cout);
  return status ? 0 : report_error(status);
}
}  // namespace

const Command kInfoCommand{"info", add_command<InfoArgs, info_options, run_info>};

}  // namespace gibake::cli
