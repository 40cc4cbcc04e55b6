// What the bake command prints when it is done: one block per stage on a terminal or in lines
// mode, one JSON object per stage with --progress json (stderr either way).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/preview/reconstruction_check.h"
#include "bake/voxel/leak_audit.h"
#include "bake/voxel/leak_probes.h"
#include "bake/voxel/voxelize.h"
#include "cli/progress.h"
#include "io/results/lpv_result.h"

namespace gibake::cli {

double peak_rss_mib();
// The bake's stages in the user's words: the set-up's parts (run side by side) right after it and
// named "set-up: <part>", the closed-mesh check as the time it added (its task runs beside the
// other stages). The seconds line and the report's table both show these.
constexpr const char* kSetupPart = "set-up: ";
std::vector<std::pair<std::string, double>> user_timings(const std::vector<std::pair<std::string, double>>& timings);
std::string seconds_text(double seconds);

// Printed after the bake summary's first line; `out` names the .vdb; `sizing` says what set the
// voxel size ("128 voxels across the longest side (--voxel-res)"), empty to say nothing.
void print_voxel_summary(const std::string& out, const VoxelReport& report, ProgressMode mode,
                         const std::string& sizing = "");

// The bake file's summary. `result`/`report` null without --ddgi, `lpv` null without --lpv.
struct BakeSummary {
  std::string out;  // the files written, for "gibake: wrote …"
  const VoxelReport* voxels = nullptr;
  std::string voxels_out;
  std::string voxels_sizing;  // see print_voxel_summary
  const DdgiResult* result = nullptr;
  const DdgiReport* report = nullptr;
  float target_error = 0.f;  // the DDGI bake's --target-error (0: not adaptive, or not known: merge)
  const LpvResult* lpv = nullptr;
  const LeakAudit* leaks = nullptr;  // null when the audit did not run
  const ReconstructionError* reconstruction = nullptr;  // null when the check did not run
  const std::vector<LeakExposure>* leak_exposure = nullptr;  // one per region of `leaks`
  std::vector<std::pair<std::string, double>> timings;  // import, stages…, write, total (seconds)
  const BackendChoice* backend = nullptr;  // the DDGI bake's backend (with auto's decision)
  // Several probe volumes (bake/ddgi/volumes.h): one line each and the JSON array; empty for one grid.
  std::vector<std::string> volume_lines;
  std::string volumes_json;
  std::string volume_rule;  // what the automatic detail-volume rule found ("" when it did not run)
  std::string refine_rule;  // what refinement placed ("" when not asked for)
  std::string quality;      // --quality: the level and what it chose (cli/bake_args.h quality_summary)
};
void print_bake_summary(const BakeSummary& s, ProgressMode mode);

// The reconstruction check's figures (the summary's "reconstruction" object, verify's details).
nlohmann::json reconstruction_json(const ReconstructionError& e);

}  // namespace gibake::cli
