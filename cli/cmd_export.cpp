// gibake export probes.bin --exr DIR | --vdb FILE: files for humans and DCC tools.
#include <sys/stat.h>

#include <string>

#include "cli/commands.h"
#include "cli/help.h"
#include "io/bakefile/bake_info.h"
#include "io/export/export_exr.h"
#include "io/export/export_vdb.h"
#include "io/output/output_check.h"

namespace gibake::cli {

namespace {
struct ExportArgs {
  std::string path, exr_dir, vdb_file;
};

// --vdb against the bake file it reads; --exr is a folder (made when missing) whose parent must exist.
Status check_export_paths(const ExportArgs& config) {
  std::vector<NamedPath> outputs;
  if (!config.vdb_file.empty()) outputs.push_back({"--vdb", config.vdb_file});
  GIBAKE_TRY(check_output_paths(outputs, {{"bake file", config.path}}));
  if (config.exr_dir.empty()) return Status::ok();
  struct stat st {};
  if (::stat(config.exr_dir.c_str(), &st) == 0)
    return S_ISDIR(st.st_mode) ? Status::ok()
                               : Status::error(ExitCode::IoFailure, config.exr_dir, "--exr", "not a folder");
  std::string dir = config.exr_dir;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  return check_output_paths({{"--exr", dir}}, {});  // the folder to be made: its parent exists, writable
}

int run_export(const ExportArgs& config) {
  if (Status s = check_export_paths(config); !s) return report_error(s);
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

// --exr or --vdb, at least one: checked with the other options, before anything runs.
void add_export(CLI::App& sub, CliState& state) {
  auto a = std::make_shared<ExportArgs>();
  sub.description("Export a bake file as EXR images and/or an OpenVDB file");
  sub.footer("Writes what --exr and --vdb name (at least one) and prints the paths written.\n"
             "Every option at length: docs/cli/export.md");
  sub.add_option("FILE", a->path, "the bake file")->required()->group("Input and output");
  OptionGroup g(sub, "Input and output");
  CLI::Option* exr = g.option("--exr", a->exr_dir, "DIR", "folder for the irradiance, depth and SH EXR images");
  CLI::Option* vdb = g.option("--vdb", a->vdb_file, "FILE", "OpenVDB file of the probe grids and volumes");
  sub.callback([&state, a, exr, vdb] {
    if (exr->count() == 0 && vdb->count() == 0) throw CLI::RequiredError("--exr or --vdb");
    state.run = [a] { return run_export(*a); };
  });
}

}  // namespace

const Command kExportCommand{"export", add_export};

}  // namespace gibake::cli
