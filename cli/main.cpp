// gibake: argv -> subcommand config -> library call -> exit code.
#include <algorithm>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "cli/commands.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.0.0"
#endif

namespace {

using gibake::cli::Command;

// The subcommands, in the order `gibake --help` lists them.
const Command* const kCommands[] = {
    &gibake::cli::kBakeCommand,   &gibake::cli::kInspectCommand, &gibake::cli::kInfoCommand,
    &gibake::cli::kVerifyCommand, &gibake::cli::kExportCommand,  &gibake::cli::kPreviewCommand,
    &gibake::cli::kMergeCommand,  &gibake::cli::kSampleCommand};

bool is_subcommand(const std::string& arg) {
  for (const Command* c : kCommands)
    if (arg == c->name) return true;
  return false;
}

// `gibake scene.gltf --ddgi` means `gibake bake scene.gltf --ddgi`.
std::vector<std::string> with_implied_bake(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) return args;
  const std::string& first = args.front();
  const bool top_level_flag = first == "-h" || first == "--help" || first == "--version";
  if (!is_subcommand(first) && !top_level_flag) args.insert(args.begin(), "bake");
  return args;
}

constexpr const char* kExamples = R"(
The subcommand 'bake' is implied: 'gibake scene.gltf --ddgi ...' is 'gibake bake scene.gltf --ddgi ...'.

Examples:
  gibake scene.gltf --ddgi --out probes.gibake                        bake DDGI probes
  gibake Sponza.gltf --ddgi --sun 0.3,-1,0.2:100000 --out sponza.gibake   a scene without lights
  gibake scene.gltf --voxels scene.vdb                                voxelize into OpenVDB grids
  gibake scene.gltf --lpv --out lpv.gibake                            light propagation volumes
  gibake inspect scene.gltf                                           what the importer sees
  gibake info probes.gibake                                           what a bake file holds
  gibake verify probes.gibake --scene scene.gltf                      integrity, sanity, staleness
  gibake preview scene.gltf --bake probes.gibake --out view.png       render a view of the bake

'gibake <command> --help' lists every option of a command.)";

// CLI11's "Could not convert: --seed = -1" in the user's words: what the option takes (from the
// type CLI11 converts to) and what it got. The shared checks (cli/options.h) catch most values
// before the conversion; this covers every other number option.
std::string conversion_message(CLI::App& app, const CLI::ConversionError& e) {
  const std::string what = e.what(), head = "Could not convert: ";
  const size_t eq = what.find(" = ");
  if (what.rfind(head, 0) != 0 || eq == std::string::npos) return what;
  const std::string name = what.substr(head.size(), eq - head.size()), value = what.substr(eq + 3);
  std::string kind = "a value of this option's kind";
  for (CLI::App* sub : app.get_subcommands()) {
    const CLI::Option* opt = sub->get_option_no_throw(name);
    if (!opt) continue;
    const std::string type = opt->get_type_name();
    if (type == "UINT") kind = "a whole number, 0 or more";
    else if (type == "INT") kind = "a whole number";
    else if (type == "FLOAT") kind = "a number";
  }
  return name + ": expected " + kind + ", got '" + value + "'";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace gibake::cli;
  CLI::App app{"gibake: offline global-illumination baker (DDGI probes, voxels and LPVs from glTF scenes)", "gibake"};
  app.set_version_flag("--version", std::string("gibake ") + GIBAKE_VERSION);
  app.require_subcommand(1);
  CliState state;
  for (const Command* c : kCommands) c->add(*app.add_subcommand(c->name), state);
  app.footer(kExamples);  // after the subcommands, which would inherit it

  std::vector<std::string> args = with_implied_bake(argc, argv);
  if (args.empty()) {  // bare `gibake`: what it does and how to call it
    std::cout << app.help();
    return static_cast<int>(gibake::ExitCode::BadArguments);
  }
  std::reverse(args.begin(), args.end());  // CLI11 consumes a reversed vector
  try {
    app.parse(args);
  } catch (const CLI::ConversionError& e) {
    std::cerr << "gibake: error: " << conversion_message(app, e) << "\n";
    return static_cast<int>(gibake::ExitCode::BadArguments);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "gibake: error: " << e.what() << "\n";
    return static_cast<int>(gibake::ExitCode::BadArguments);
  }
  if (!state.run) return static_cast<int>(gibake::ExitCode::BadArguments);
  try {
    return state.run();
  } catch (const std::bad_alloc&) {
    std::cerr << "gibake: error: out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << "gibake: error: " << e.what() << "\n";
  }
  return static_cast<int>(gibake::ExitCode::RuntimeFailure);
}
