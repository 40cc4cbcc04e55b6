// gibake verify probes.bin [--against ref.bin] [--tolerance T] [--scene scene.gltf]
//                          [--format text|json]
#include <string>

#include "bake/preview/reconstruction_check.h"
#include "bake/scene/prepare.h"
#include "bake/scene/texture_lod.h"
#include "cli/bake_summary.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_verify.h"
#include "io/gltf/import.h"

namespace gibake::cli {
namespace {

// --max-reconstruction-error E: the bake's reconstruction check (bake/preview/reconstruction_check.h)
// against --scene; fails (exit 7) when the worst tenth of its patches is off by more than E.
void check_reconstruction(const VerifyOptions& options, double max_error, const Context& ctx, VerifyReport& report) {
  Scene scene;
  std::unique_ptr<PreparedScene> prepared;
  loader::BakeFile file;
  Status st = import_scene(options.scene, ImportOptions{}, ctx, scene);
  if (st) st = PreparedScene::create(scene, ctx, prepared);
  if (st) st = open_bake_file(options.path, file);
  ReconstructionError e;
  if (st) st = measure_bake_reconstruction(*prepared, TextureLod(scene, ctx), file, nullptr, ReconstructionSettings{}, ctx, e);
  if (!st) {
    verify_detail::add(report, "reconstruction", "fail", st.message());
    report.exit_code = static_cast<int>(st.code());
    return;
  }
  const bool ok = e.counted > 0 && e.shaded.p90_error <= max_error;
  nlohmann::json details = reconstruction_json(e);
  details["max_error"] = max_error;
  verify_detail::add(report, "reconstruction", ok ? "pass" : "fail", reconstruction_summary(e), details);
  if (!ok && report.exit_code == 0) report.exit_code = static_cast<int>(ExitCode::VerifyMismatch);
}

struct VerifyArgs {
  VerifyOptions options;
  std::string format = "text";
  double max_reconstruction_error = -1.0;  // < 0: no reconstruction check
};

void verify_options(CLI::App& sub, VerifyArgs& a) {
  sub.description("Check a bake file: integrity, sanity, staleness, differences");
  sub.add_option("file", a.options.path, "Bake file")->required();
  sub.add_option("--against", a.options.against, "Reference bake file to compare with");
  sub.add_option("--tolerance", a.options.tolerance, "Per value: |a-ref| <= T*max(1,|ref|) (default 1e-4)")
      ->check(non_negative_number());
  sub.add_option("--scene", a.options.scene, "Scene for the staleness and energy checks");
  sub.add_option("--format", a.format, "Report format")->check(CLI::IsMember({"text", "json"}));
  sub.add_option("--max-reconstruction-error", a.max_reconstruction_error,
                 "with --scene: fail (exit 7) when the reconstruction check's worst tenth of surface patches is "
                 "off the path-traced truth by more than this fraction (e.g. 0.25)")
      ->check(CLI::NonNegativeNumber);
}

int run_verify_command(const VerifyArgs& a) {
  Context ctx;
  ctx.warn = print_warning;
  const double max_error = a.max_reconstruction_error;
  if (max_error >= 0.0 && a.options.scene.empty()) {
    std::cerr << "gibake: error: --max-reconstruction-error: needs --scene (the scene the bake was made from)\n";
    return static_cast<int>(ExitCode::BadArguments);
  }
  VerifyReport report = run_verify(a.options, ctx);
  if (max_error >= 0.0 && report.error.empty()) check_reconstruction(a.options, max_error, ctx, report);
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
