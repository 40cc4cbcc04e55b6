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

void info_options(CLI::App& sub, InfoArgs& a) {
  sub.description("Show what a bake file holds (sections, metadata, volumes)");
  sub.add_option("file", a.path, "Bake file");
  sub.add_flag("--devices", a.devices, "List the Vulkan devices (for --backend / --vulkan-device)");
  sub.add_flag("--probes", a.probes, "List every probe (coordinate, position, state, SH)");
  sub.add_option("--format", a.format, "Output format")->check(CLI::IsMember({"text", "json"}));
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
