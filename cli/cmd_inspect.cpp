// gibake inspect scene.gltf [--format text|json] [--check-self-intersections] [--no-textures]
// What the importer sees: counts, materials, textures, lights, bounds and mesh diagnostics.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/volume_plan.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "cli/commands.h"
#include "cli/help.h"
#include "bake/voxel/leak_warnings.h"
#include "cli/options.h"
#include "io/inspect/inspect_report.h"
#include "io/results/voxel_grid.h"

namespace gibake::cli {
namespace {

struct InspectArgs {
  std::string scene;
  std::string format = "text";
  bool check_self_intersections = false;
  bool no_textures = false;
  std::string leak_audit = "on";
  std::vector<std::string> suns;
};

void inspect_options(CLI::App& sub, InspectArgs& a) {
  sub.description("Show what the importer sees in a glTF scene, with mesh checks and a leak audit");
  sub.footer("Prints counts, materials, textures, lights, bounds and mesh diagnostics; exit 3 on a bad file.\n"
             "Every option at length: docs/cli/inspect.md");
  sub.add_option("SCENE", a.scene, "the scene: a .gltf or .glb file")->required()->group("Input and output");
  OptionGroup out(sub, "Input and output");
  out.option("--format", a.format, "text|json", "report format on stdout")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
  out.flag("--no-textures", a.no_textures, "do not decode images (texture sizes may then be unknown)");
  OptionGroup checks(sub, "Checks");
  checks.flag("--check-self-intersections", a.check_self_intersections,
              "also look for intersecting triangles (slow on large scenes)");
  checks.option("--leak-audit", a.leak_audit, "on|off", "warn where a thin wall parts lit from unlit space")
      ->capture_default_str();
  checks.option("--sun", a.suns, "dx,dy,dz:lux[:r,g,b]", "directional light for the leak audit; repeatable");
}

// The bake's leak audit for the default grid, planned as a default bake plans it (its budget cut
// where the detail rule adds a volume): the voxels it was fitted to, the scene's lights, emissive
// surfaces and --sun, so that inspect warns where the bake would. Warnings name each region.
Status audit_scene_leaks(const Scene& scene, const std::vector<SunLight>& suns, const std::string& format,
                         const Context& ctx, LeakAudit& audit, bool& ran) {
  DdgiSettings settings;
  settings.suns = suns;
  if (scene.bounds.empty()) return Status::ok();
  VolumePlan plan;
  VolumeSettings volumes;
  volumes.refine.budget = 0;  // the audit reads the default grid, which refinement leaves as it is
  GIBAKE_TRY(plan_ddgi_volumes(scene, settings, volumes, ctx, plan));
  const float spacing = coarsest_spacing(plan.volumes[0].placed.desc.spacing);
  if (!(spacing > 0.f) || plan.voxels.empty()) return Status::ok();
  std::unique_ptr<PreparedScene> prepared;
  GIBAKE_TRY(PreparedScene::create(scene, ctx, prepared));
  GIBAKE_TRY(audit_and_warn(plan.voxels, *prepared, shade_lights(scene, settings.suns), spacing, ctx, audit, ran));
  if (audit.regions_total == 0 && format == "text")
    std::fprintf(stderr, "gibake: leak audit: no wall under %.3g m (the default probe spacing) separates lit from "
                 "unlit space\n", double(spacing));
  return Status::ok();
}

int run_inspect(const InspectArgs& config) {
  Context ctx;
  ctx.warn = print_warning;
  InspectOptions options;
  options.check_self_intersections = config.check_self_intersections;
  options.load_textures = !config.no_textures;
  bool leak_audit = true;  // both checked before the import
  if (Status st = parse_on_off("--leak-audit", config.leak_audit, leak_audit); !st) return report_error(st);
  std::vector<SunLight> suns;
  if (Status st = parse_suns(config.suns, suns); !st) return report_error(st);
  InspectResult result;
  const Status status = inspect_scene(config.scene, options, ctx, result);
  if (!status) return report_error(status);
  LeakAudit audit;
  bool audited = false;
  if (leak_audit) {
    if (Status st = audit_scene_leaks(result.scene, suns, config.format, ctx, audit, audited); !st)
      return report_error(st);
  }
  if (config.format == "json") {
    std::string text = inspect_report_json(result.scene, result.diagnostics);
    if (audited) {  // every region, where the warnings name only the largest
      nlohmann::json j = nlohmann::json::parse(text);
      j["leak_audit"] = leak_json(audit, nullptr);
      text = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    }
    std::cout << text;
  } else
    std::cout << inspect_report_text(result.scene, result.diagnostics);
  std::cout.flush();
  if (!std::cout) {
    return report_error(Status::io("<stdout>", "cannot write the report"));
  }
  return static_cast<int>(ExitCode::Ok);
}

}  // namespace

const Command kInspectCommand{"inspect", add_command<InspectArgs, inspect_options, run_inspect>};

}  // namespace gibake::cli
