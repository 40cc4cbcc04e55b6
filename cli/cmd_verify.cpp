// gibake verify probes.bin [--against ref.bin] [--tolerance T] [--scene scene.gltf]
//                          [--format text|json]
#include <string>

#include "cli/commands.h"
#include "cli/options.h"
#include "io/bakefile/bake_verify.h"

namespace gibake::cli {

void add_verify_command(CLI::App& app, CliState& state) {
  auto config = std::make_shared<VerifyOptions>();
  auto format = std::make_shared<std::string>("text");
  CLI::App* sub = app.add_subcommand("verify", "Check a bake file: integrity, sanity, staleness, differences");
  sub->add_option("file", config->path, "Bake file")->required();
  sub->add_option("--against", config->against, "Reference bake file to compare with");
  sub->add_option("--tolerance", config->tolerance, "Per value: |a-ref| <= T*max(1,|ref|) (default 1e-4)")
      ->check(non_negative_number());
  sub->add_option("--scene", config->scene, "Scene for the staleness and energy checks");
  sub->add_option("--format", *format, "Report format")->check(CLI::IsMember({"text", "json"}));
  sub->callback([&state, config, format] {
    state.run = [config, format] {
      Context ctx;
      ctx.warn = print_warning;
      const VerifyReport report = run_verify(*config, ctx);
      if (*format == "json")
        std::cout << verify_report_json(report).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
      else
        print_verify_text(report, std::cout);
      if (!report.error.empty()) std::cerr << "gibake: error: " << report.error << "\n";
      return report.exit_code;
    };
  });
}

}  // namespace gibake::cli
