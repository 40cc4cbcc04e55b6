// gibake inspect scene.gltf [--format text|json] [--check-self-intersections] [--no-textures]
// What the importer sees: counts, materials, textures, lights, bounds and mesh diagnostics.
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "io/inspect_report.h"

namespace gibake::cli {
namespace {

struct InspectConfig {
  std::string scene;
  std::string format = "text";
  bool check_self_intersections = false;
  bool no_textures = false;
};

int run_inspect(const InspectConfig& config) {
  Context ctx;
  ctx.warn = print_warning;
  InspectOptions options;
  options.check_self_intersections = config.check_self_intersections;
  options.load_textures = !config.no_textures;
  InspectResult result;
  const Status status = inspect_scene(config.scene, options, ctx, result);
  if (!status) return report_error(status);
  if (config.format == "json")
    std::cout << inspect_report_json(result.scene, result.diagnostics);
  else
    std::cout << inspect_report_text(result.scene, result.diagnostics);
  std::cout.flush();
  if (!std::cout) {
    return report_error(Status::io("<stdout>", "cannot write the report"));
  }
  return static_cast<int>(ExitCode::Ok);
}

}  // namespace

void add_inspect_command(CLI::App& app, CliState& state) {
  auto config = std::make_shared<InspectConfig>();
  CLI::App* sub = app.add_subcommand("inspect", "Show what the importer sees in a glTF/GLB scene");
  sub->add_option("scene", config->scene, "Scene file (.gltf or .glb)")->required();
  sub->add_option("--format", config->format, "Report format")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
  sub->add_flag("--check-self-intersections", config->check_self_intersections,
                "Also look for intersecting triangle pairs (slow on large scenes)");
  sub->add_flag("--no-textures", config->no_textures,
                "Do not decode images (texture sizes may then be unknown)");
  sub->callback([&state, config] { state.run = [config] { return run_inspect(*config); }; });
}

}  // namespace gibake::cli
