// gibake export probes.gibake --exr DIR | --vdb FILE: files for humans and DCC tools.
#include <sys/stat.h>
#include <unistd.h>

#include <set>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/help.h"
#include "cli/options.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_verify.h"
#include "io/export/export_exr.h"
#include "io/export/export_vdb.h"
#include "io/output/bake_atomic.h"
#include "io/output/output_check.h"

namespace gibake::cli {

namespace {
struct ExportArgs {
  std::string path, exr_dir, vdb_file;
};

bool path_exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

std::string without_trailing_slashes(std::string dir) {
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  return dir;
}

// The paths as given, before the bake file is read: --vdb's name, --vdb and --exr not one path,
// --vdb not the bake file and writable, --exr a folder or one to be made in an existing folder.
Status check_given_paths(const ExportArgs& config) {
  const std::string exr_dir = without_trailing_slashes(config.exr_dir);
  if (!config.vdb_file.empty()) {
    GIBAKE_TRY(check_output_kind("--vdb", config.vdb_file, {".vdb"}, "an OpenVDB file"));
    if (!exr_dir.empty() && names_same_file(config.vdb_file, exr_dir))
      return Status::error(
          ExitCode::BadArguments, config.vdb_file, "--vdb",
          "names the folder --exr writes into (" + config.exr_dir + "); give each output its own path");
    GIBAKE_TRY(check_output_paths({{"--vdb", config.vdb_file}}, {{"bake file", config.path}}));
  }
  if (exr_dir.empty()) return Status::ok();
  struct stat st {};
  if (::stat(exr_dir.c_str(), &st) == 0)
    return S_ISDIR(st.st_mode) ? Status::ok()
                               : Status::error(ExitCode::IoFailure, config.exr_dir, "--exr", "not a folder");
  return check_output_paths({{"--exr", exr_dir}}, {});  // the folder to be made: its parent exists, writable
}

// Every file the export will write, once the bake file says what it holds, checked before any is
// written. In a folder still to be made no EXR file exists yet, so only --vdb has anything to meet.
Status check_planned_outputs(const ExportArgs& config, const loader::BakeFile& file) {
  std::vector<NamedPath> outputs;
  if (!config.exr_dir.empty()) {
    if (file.ddgi_volumes().empty())
      return Status::invalid(config.path, "--exr",
                             "the bake file has no DDGI volume, whose probes the EXR images hold");
    if (path_exists(config.exr_dir))
      for (const std::string& p : exr_file_paths(file, config.exr_dir)) outputs.push_back({"--exr", p});
  }
  if (!config.vdb_file.empty()) {
    if (file.ddgi_volumes().empty() && file.lpv_cascades().empty() && file.vxgi_volumes().empty())
      return Status::invalid(config.path, "--vdb", "the bake file has no DDGI volume, LPV cascade or voxel GI volume");
    outputs.push_back({"--vdb", config.vdb_file});
  }
  return check_output_paths(outputs, {{"bake file", config.path}});
}

int run_export(const ExportArgs& config) {
  if (Status s = check_given_paths(config); !s) return report_error(s);
  loader::BakeFile file;
  if (Status s = open_bake_file(config.path, file); !s) return report_error(s);
  if (Status s = check_values_readable(file, config.path); !s) return report_error(s);
  if (Status s = check_planned_outputs(config, file); !s) return report_error(s);
  // A write can still fail (a full disk): then what this run created goes, the --exr folder too
  // if it made it, so that a failed export leaves nothing behind. A file that existed before and
  // was already replaced keeps its new bytes: each file is replaced whole, never half-written.
  const bool made_dir = !config.exr_dir.empty() && !path_exists(config.exr_dir);
  std::set<std::string> existed;
  std::vector<std::string> targets =
      config.exr_dir.empty() ? std::vector<std::string>{} : exr_file_paths(file, config.exr_dir);
  if (!config.vdb_file.empty()) targets.push_back(config.vdb_file);
  for (const std::string& p : targets)
    if (path_exists(p)) existed.insert(p);
  // A signal mid-way removes them as a failure below does: registered before the folder is made.
  ProvisionalOutputs made;
  for (const std::string& p : targets)
    if (existed.count(p) == 0) made.add_file(p);
  if (made_dir) made.add_folder(config.exr_dir);
  std::vector<std::string> written;
  Status st = Status::ok();
  if (!config.exr_dir.empty()) st = export_exr(file, config.exr_dir, &written);
  if (st && !config.vdb_file.empty()) {
    st = export_vdb(file, config.vdb_file);
    if (st) written.push_back(config.vdb_file);
  }
  if (!st) {
    for (const std::string& p : written)
      if (existed.count(p) == 0) ::unlink(p.c_str());
    if (made_dir) ::rmdir(config.exr_dir.c_str());  // only when empty: nothing but this run's files
    return report_error(st);
  }
  made.keep();
  for (const std::string& p : written) std::cout << p << "\n";
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
