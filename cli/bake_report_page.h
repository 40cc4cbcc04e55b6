// --report: the bake's HTML page, with lit and probes previews rendered from the file just written.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/volumes.h"
#include "bake/preview/reconstruction_check.h"
#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"
#include "io/timer.h"

namespace gibake::cli {

struct ReportPageInputs {
  std::string page;        // the .html to write
  std::string scene_path;  // as given on the command line
  std::string bake_path;   // the bake file just written (read back as an engine would)
  float blend_cutoff = kDefaultBlendCutoff;
  const Scene* scene = nullptr;
  const DdgiResult* result = nullptr;
  const DdgiReport* report = nullptr;
  const std::vector<BakedVolume>* volumes = nullptr;    // every volume, when several (BakeReportInputs)
  std::vector<std::pair<std::string, double>> timings;  // the bake's stages so far
  Clock::time_point bake_start;                         // for the page's own "report" and "total" rows
  std::vector<std::string> warnings;                    // every warning the bake printed
  std::vector<std::string> leak_regions;                // every leak-audit region, warned or not
  const ReconstructionError* reconstruction = nullptr;  // the bake's reconstruction check, when it ran
  // The first --check-camera (cli/check_camera.h), if any: the page's views are taken from it, so
  // that the check's patches marked on the lit view are the ones that view shows.
  std::string view;
  float view_fov = 0.f;
  std::string volumes_json;  // several probe volumes (bake/ddgi/volumes.h): shown with the settings
  std::string quality;       // --quality's level and what it chose: shown with the settings
};

Status write_report_page(const ReportPageInputs& in, const Context& ctx);

}  // namespace gibake::cli
