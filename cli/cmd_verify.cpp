// gibake verify probes.bin [--against ref.bin [--compare values|statistical] [--tolerance T]
//                          [--sigmas K] [--max-fraction F]] [--scene scene.gltf] [--require KINDS]
//                          [--format text|json]
#include <algorithm>
#include <string>
#include <vector>

#include "bake/preview/reconstruction_check.h"
#include "bake/scene/prepare.h"
#include "bake/scene/texture_lod.h"
#include "cli/bake_summary.h"
#include "cli/check_camera.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_verify.h"
#include "io/gltf/import.h"

namespace gibake::cli {
namespace {

struct ReconstructionArgs {
  double max_error = -1.0;           // < 0: no reconstruction check
  std::vector<std::string> cameras;  // --check-camera (cli/check_camera.h); none: the probes' view
  float fov = 0.f;
  uint32_t patches = 128, rays = 128;
};

// --max-reconstruction-error E: the bake's reconstruction check (bake/preview/reconstruction_check.h)
// against --scene; fails (exit 7) when the worst tenth of its patches is off by more than E.
void check_reconstruction(const VerifyOptions& options, const ReconstructionArgs& a, const Context& ctx,
                          VerifyReport& report) {
  Scene scene;
  std::unique_ptr<PreparedScene> prepared;
  loader::BakeFile file;
  ReconstructionSettings rs;
  rs.patches = a.patches;
  rs.rays = a.rays;
  rs.width = kCheckWidth;
  rs.height = kCheckHeight;
  Status st = import_scene(options.scene, ImportOptions{}, ctx, scene);
  if (st) st = resolve_check_cameras(scene, a.cameras, a.fov, rs.cameras);
  if (st) st = PreparedScene::create(scene, ctx, prepared);
  if (st) st = open_bake_file(options.path, file);
  ReconstructionError e;
  if (st) st = measure_bake_reconstruction(*prepared, TextureLod(scene, ctx), file, nullptr, rs, ctx, e);
  if (!st) {
    verify_detail::add(report, "reconstruction", "fail", st.message());
    report.exit_code = static_cast<int>(st.code());
    return;
  }
  const bool ok = e.counted > 0 && e.shaded.p90_error <= a.max_error;
  nlohmann::json details = reconstruction_json(e);
  details["max_error"] = a.max_error;
  verify_detail::add(report, "reconstruction", ok ? "pass" : "fail", reconstruction_summary(e), details);
  if (!ok && report.exit_code == 0) report.exit_code = static_cast<int>(ExitCode::VerifyMismatch);
}

struct VerifyArgs {
  VerifyOptions options;
  std::string format = "text";
  ReconstructionArgs reconstruction;
  CLI::Option* sigmas = nullptr;  // --sigmas, --max-fraction: whether given, they need --compare statistical
  CLI::Option* max_fraction = nullptr;
};

void verify_options(CLI::App& sub, VerifyArgs& a) {
  sub.description("Check a bake file: integrity, sanity, staleness, differences");
  sub.footer(
      "Checks that cannot run (no --scene, no --against, no --max-reconstruction-error) are listed as skipped\n"
      "with the reason; --require makes a skipped kind fail (exit 7).\n"
      "--compare statistical, for bakes of one scene and settings on other backends or seeds, fails a volume\n"
      "when more than --max-fraction of its probe states differ, of its probes' SH irradiance (worst of 64\n"
      "directions) or of its irradiance texels differ by more than --sigmas x their recorded noise (x2, x3),\n"
      "of its relocation offsets move 0.1 spacing apart, or of its depth texels differ by more than half of\n"
      "max(distance, spacing); or when its mean irradiance differs by more than --sigmas x its noise and 0.5%.");
  sub.add_option("file", a.options.path, "Bake file")->required();
  sub.add_option("--against", a.options.against, "Reference bake file to compare with");
  sub.add_option("--compare", a.options.compare,
                 "values (each within --tolerance) or statistical (within the probes' noise) (default values)")
      ->check(CLI::IsMember({"values", "statistical"}));
  sub.add_option("--tolerance", a.options.tolerance, "Per value: |a-ref| <= T*max(1,|ref|) (default 1e-4)")
      ->check(non_negative_number());
  a.sigmas = sub.add_option("--sigmas", a.options.statistical.sigmas,
                 "statistical: a difference over K x the pair's noise is beyond (default 5)")
      ->check(CLI::PositiveNumber);
  a.max_fraction = sub.add_option("--max-fraction", a.options.statistical.max_fraction,
                 "statistical: share of states, probes or texels allowed beyond (default 0.01)")
      ->check(CLI::Range(0.0, 1.0));
  sub.add_option("--scene", a.options.scene, "Scene for the staleness, lit and energy checks (else skipped)");
  sub.add_option("--require", a.options.require,
                 "fail when these are skipped: staleness,lit,energy,against,reconstruction,scene,all (default none)")
      ->delimiter(',')
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  sub.add_option("--format", a.format, "Report format")->check(CLI::IsMember({"text", "json"}));
  sub.add_option("--max-reconstruction-error", a.reconstruction.max_error,
                 "with --scene: fail (exit 7) when the reconstruction check's worst tenth of surface patches is "
                 "off the path-traced truth by more than this fraction (e.g. 0.25)")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--check-camera", a.reconstruction.cameras,
                 "with --max-reconstruction-error: patches from this view instead of the probes' view ('default', "
                 "'gltf:N' or ex,ey,ez,tx,ty,tz,ux,uy,uz); repeat for several views")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  sub.add_option("--check-fov", a.reconstruction.fov, "vertical field of view of --check-camera, degrees");
  sub.add_option("--check-patches", a.reconstruction.patches, "4x4-point patches of the check (default 128)")
      ->check(CLI::Range(1u, 1u << 20));
  sub.add_option("--check-rays", a.reconstruction.rays, "reference paths per point of the check (default 128)")
      ->check(CLI::Range(1u, 1u << 16));
}

// --require's list with scene and all spelled out; BadArguments for an unknown kind.
Status expand_requirements(std::vector<std::string>& kinds) {
  std::vector<std::string> out;
  auto push = [&out](const std::string& k) {
    if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  };
  for (const std::string& k : kinds) {
    if (k == "all") {
      for (const std::string& x : requirable_checks()) push(x);
    } else if (k == "scene") {
      for (const char* x : {"staleness", "lit", "energy"}) push(x);
    } else if (std::find(requirable_checks().begin(), requirable_checks().end(), k) != requirable_checks().end()) {
      push(k);
    } else {
      return Status::error(ExitCode::BadArguments, "", "--require",
                           "unknown check '" + k + "' (expected staleness, lit, energy, against, reconstruction, scene "
                           "or all)");
    }
  }
  kinds = std::move(out);
  return Status::ok();
}

int run_verify_command(const VerifyArgs& given) {
  Context ctx;
  ctx.warn = print_warning;
  VerifyArgs a = given;
  if (Status st = expand_requirements(a.options.require); !st) return report_error(st);
  if ((a.sigmas->count() > 0 || a.max_fraction->count() > 0) && a.options.compare != "statistical") {
    std::cerr << "gibake: error: --sigmas, --max-fraction: only with --compare statistical\n";
    return static_cast<int>(ExitCode::BadArguments);
  }
  const bool checks = a.reconstruction.max_error >= 0.0;
  if (checks && a.options.scene.empty()) {
    std::cerr << "gibake: error: --max-reconstruction-error: needs --scene (the scene the bake was made from)\n";
    return static_cast<int>(ExitCode::BadArguments);
  }
  if (!checks && !a.reconstruction.cameras.empty()) {
    std::cerr << "gibake: error: --check-camera: only with --max-reconstruction-error\n";
    return static_cast<int>(ExitCode::BadArguments);
  }
  if (Status st = check_camera_specs(a.reconstruction.cameras, a.reconstruction.fov); !st) return report_error(st);
  VerifyReport report = run_verify(a.options, ctx);
  if (checks && report.error.empty()) check_reconstruction(a.options, a.reconstruction, ctx, report);
  if (!checks && report.error.empty())
    verify_detail::add(report, "reconstruction", "skip", "needs --max-reconstruction-error E (with --scene)");
  if (report.error.empty()) apply_requirements(report);
  if (a.format == "json")
    std::cout << verify_report_json(report).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  else
    print_verify_text(report, std::cout);
  if (!report.error.empty()) std::cerr << "gibake: error: " << report.error << "\n";
  return report.exit_code;
}

}  // namespace

const Command kVerifyCommand{"verify", add_command<VerifyArgs, verify_options, run_verify_command>};

}  // namespace gibake::cli
