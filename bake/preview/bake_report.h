// `gibake bake ... --report report.html`: one self-contained HTML page (no network access, images
// as base64 data URIs, histogram as inline SVG) with the settings, stage timings, probe statistics
// (counts by state, rays per probe, estimated-error histogram), warnings and preview images.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/volumes.h"
#include "bake/preview/reconstruction_check.h"
#include "io/status.h"

namespace gibake {

struct BakeReportInputs {
  std::string scene;                 // scene path as given
  std::string settings_json;         // DdgiResult::settings_json
  std::vector<std::pair<std::string, double>> timings;  // stage, seconds (in order)
  const DdgiReport* report = nullptr;                   // volume 0's, as `result`
  const DdgiResult* result = nullptr;
  // Every volume, when the bake has several: a table of them all, and the grid, probe and ray
  // sections say that they are volume 0's.
  const std::vector<BakedVolume>* volumes = nullptr;
  std::vector<std::string> warnings;
  std::vector<std::string> leak_regions;  // every leak-audit region (the warnings hold the worst)
  // The bake's reconstruction check (null: not run) and the lit view with its patches marked.
  const ReconstructionError* reconstruction = nullptr;
  std::vector<uint8_t> reconstruction_png;
  // Embedded previews: caption and PNG bytes.
  std::vector<std::pair<std::string, std::vector<uint8_t>>> images;
};

// The page as a string.
std::string bake_report_html(const BakeReportInputs& in);
// Written atomically, refusing to overwrite any of `inputs`.
Status write_bake_report(const std::string& path, const BakeReportInputs& in, const std::vector<std::string>& inputs);

}  // namespace gibake
