// gibake export probes.bin --exr DIR | --vdb FILE: files for humans and DCC tools.
#include <string>

#include "cli/commands.h"
#include "io/bakefile/bake_info.h"
#include "io/export/export_exr.h"
#include "io/export/export_vdb.h"

namespace gibake::cli {

namespace {
struct ExportConfig {
  std::string path, exr_dir, vdb_file;
};

int run_export(const ExportConfig& config) {
  loader::BakeFile file;
  if (Status s = open_bake_file(config.path, file); !s) return report_error(s);
  if (!config.exr_dir.empty()) {
    std::vector<std::string> written;
    if (Status s = export_exr(file, config.exr_dir, &written); !s) return report_error(s);
    for (const std::string& p : written) std::cout << p << "\n";
  }
  if (!config.vdb_file.empty()) {
    if (Status s = export_vdb(file, config.vdb_file); !s) return report_error(s);
    std::cout << config.vdb_file << "\n";
  }
  return 0;
}
}  // namespace

void add_export_command(CLI::App& app, CliState& state) {
  auto config = std::make_shared<ExportConfig>();
  CLI::App* sub = app.add_subcommand("export", "Export a bake file as EXR images and/or an OpenVDB grid file");
  sub->add_option("file", config->path, "Bake file")->required();
  CLI::Option* exr = sub->add_option("--exr", config->exr_dir, "Folder for irradiance/depth/SH EXR images");
  CLI::Option* vdb = sub->add_option("--vdb", config->vdb_file, "OpenVDB file of the probe grid");
  sub->callback([&state, config, exr, vdb] {
    if (exr->count() == 0 && vdb->count() == 0) throw CLI::RequiredError("--exr or --vdb");
    state.run = [config] { return run_export(*config); };
  });
}

}  // namespace gibake::cli
