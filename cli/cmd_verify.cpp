// gibake verify probes.gibake [--against ref.gibake [--compare values|statistical] [--tolerance T]
//                             [--sigmas K] [--max-fraction F]] [--scene scene.gltf] [--require KINDS]
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
  float noise = 0.03f;      // --check-noise (ReconstructionSettings::target_noise)
  uint32_t ray_budget = 0;  // --check-ray-budget (0: the default)
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
  rs.target_noise = a.noise;
  rs.ray_budget = a.ray_budget;
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
  CLI::Option* compare = nullptr;  // --compare, --tolerance: whether given, they need --against
  CLI::Option* tolerance = nullptr;
};

void verify_options(CLI::App& sub, VerifyArgs& a) {
  sub.description("Check a bake file: integrity, sanity, staleness, differences");
  sub.footer(
      "Exit 0: every check that ran passed; 3: the file is invalid (integrity or sanity: NaN/Inf, a\n"
      "negative texel, an undefined probe state...); 7: a difference (--against, staleness, lit, energy,\n"
      "reconstruction) or a required check skipped. The report goes to stdout.\n"
      "Checks that cannot run are listed as skipped; --require makes a skipped kind fail.\n"
      "Every option at length: docs/cli/verify.md");
  const std::string io = "Input and output", compare = "Comparison", scene = "Scene checks (--scene)";
  sub.add_option("FILE", a.options.path, "the bake file")->required()->group(io);
  sub.add_option("--format", a.format, "report format on stdout")
      ->check(CLI::IsMember({"text", "json"}))
      ->group(io)->option_text("text|json")->capture_default_str();
  sub.add_option("--require", a.options.require, "kinds that must run: staleness, lit, energy, against, ...")
      ->delimiter(',')
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->group(io)->option_text("KINDS");
  sub.add_option("--against", a.options.against, "a reference bake file to compare with")
      ->group(compare)->option_text("FILE");
  a.compare = sub.add_option("--compare", a.options.compare, "value by value, or statistical: within the noise")
                  ->check(CLI::IsMember({"values", "statistical"}))
                  ->group(compare)
                  ->option_text("values|statistical")
                  ->capture_default_str();
  a.tolerance = sub.add_option("--tolerance", a.options.tolerance, "per value: |a - ref| <= T max(1, |ref|)")
                    ->check(non_negative_number())
                    ->group(compare)
                    ->option_text("T")
                    ->capture_default_str();
  a.sigmas = sub.add_option("--sigmas", a.options.statistical.sigmas, "statistical: beyond K x the pair's noise")
                 ->check(positive_number())
                 ->group(compare)
                 ->option_text("K")
                 ->capture_default_str();
  a.max_fraction =
      sub.add_option("--max-fraction", a.options.statistical.max_fraction, "statistical: share allowed beyond")
          ->check(CLI::Range(0.0, 1.0))
          ->group(compare)->option_text("F")->capture_default_str();
  sub.add_option("--scene", a.options.scene, "the scene it was baked from: staleness, lit and energy checks")
      ->group(scene)->option_text("FILE");
  sub.add_option("--max-reconstruction-error", a.reconstruction.max_error,
                 "fail when the check's worst tenth of patches is off by more")
      ->check(non_negative_number())
      ->group(scene)
      ->option_text("E");
  sub.add_option("--check-camera", a.reconstruction.cameras, "patches from this view: default, gltf:N or 9 numbers")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->group(scene)->option_text("VIEW");
  sub.add_option("--check-fov", a.reconstruction.fov, "vertical field of view of --check-camera (unset: the glTF's)")
      ->group(scene)->option_text("DEG");
  sub.add_option("--check-patches", a.reconstruction.patches, "4x4-point surface patches the check measures")
      ->check(CLI::Range(1u, 1u << 20))
      ->group(scene)->option_text("N")->capture_default_str();
  sub.add_option("--check-rays", a.reconstruction.rays, "reference paths per point of the check")
      ->check(CLI::Range(1u, 1u << 16))
      ->group(scene)->option_text("N")->capture_default_str();
  sub.add_option("--check-noise", a.reconstruction.noise, "trace patches noisier than this again; 0: one pass")
      ->check(CLI::Range(0.0, 1.0))
      ->group(scene)
      ->option_text("F")
      ->capture_default_str();
  sub.add_option("--check-ray-budget", a.reconstruction.ray_budget,
                 "mean paths a point, both passes [4x --check-rays, 32x from views]")
      ->check(CLI::Range(0u, 1u << 20))
      ->group(scene)
      ->option_text("N");
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
  if ((a.compare->count() > 0 || a.tolerance->count() > 0) && a.options.against.empty()) {
    std::cerr << "gibake: error: --compare, --tolerance: only with --against (the reference they compare with)\n";
    return static_cast<int>(ExitCode::BadArguments);
  }
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
  const bool invalid = report.exit_code == static_cast<int>(ExitCode::InvalidInput);
  if (checks && report.error.empty() && !invalid) check_reconstruction(a.options, a.reconstruction, ctx, report);
  if ((!checks || invalid) && report.error.empty())
    verify_detail::add(
        report, "reconstruction", "skip",
        checks ? "not run: the file failed the checks above" : "needs --max-reconstruction-error E (with --scene)");
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
