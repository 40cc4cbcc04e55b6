#include "cli/bake_report_page.h"

#include <memory>

#include "bake/preview/bake_report.h"
#include "bake/preview/preview.h"
#include "bake/scene/prepare.h"
#include "io/bakefile/bake_info.h"

namespace gibake::cli {
namespace {

// Warnings only the page adds: probe states that deserve a look in the probes view.
void add_probe_warnings(const DdgiReport& report, std::vector<std::string>& warnings) {
  if (report.cgal_inactive_outside > 0)
    warnings.push_back(std::to_string(report.cgal_inactive_outside) +
                       " inactive probes lie outside every closed solid (open geometry or thin walls: leak risk)");
  if (report.inactive > report.enclosed + int32_t(report.cgal_inside))
    warnings.push_back(std::to_string(report.inactive - report.enclosed) +
                       " probes are inactive without being enclosed: check them in the probes view");
}

}  // namespace

Status write_report_page(const ReportPageInputs& in, const Context& ctx) {
  BakeReportInputs page;
  page.scene = in.scene_path;
  page.settings_json = in.result->settings_json;
  page.timings = in.timings;
  page.report = in.report;
  page.result = in.result;
  page.warnings = in.warnings;
  add_probe_warnings(*in.report, page.warnings);
  loader::BakeFile file;
  GIBAKE_TRY(open_bake_file(in.bake_path, file));
  Context quiet = ctx;
  quiet.progress = nullptr;
  std::unique_ptr<PreparedScene> prepared;
  PrepareOptions po;
  po.blend_cutoff = in.blend_cutoff;
  GIBAKE_TRY(PreparedScene::create(*in.scene, quiet, prepared, po));
  for (PreviewMode mode : {PreviewMode::Lit, PreviewMode::Probes}) {
    PreviewSettings ps;
    ps.mode = mode;
    ps.width = 960;
    ps.height = 540;
    PreviewImage img;
    PreviewStats stats;
    GIBAKE_TRY(render_preview(*prepared, &file, ps, quiet, img, &stats));
    float ev = 0.f;
    std::vector<uint8_t> png;
    GIBAKE_TRY(encode_png(img.width, img.height, tonemap_rgb8(img, Tonemap{}, &ev), png));
    page.images.emplace_back(std::string(preview_mode_name(mode)) + " (" + stats.camera + ", EV100 " +
                                 std::to_string(ev).substr(0, 5) + ")",
                             std::move(png));
  }
  std::vector<std::string> inputs = in.scene->input_files;
  inputs.push_back(in.bake_path);
  return write_bake_report(in.page, page, inputs);
}

}  // namespace gibake::cli
