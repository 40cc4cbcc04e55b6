#include "cli/bake_report_page.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

#include "bake/preview/bake_report.h"
#include "bake/preview/preview.h"
#include "bake/scene/prepare.h"
#include "cli/bake_summary.h"
#include "cli/check_camera.h"
#include "io/bakefile/bake_info.h"

namespace gibake::cli {
namespace {

// One warning for the inactive probes, every part of it from the same total: those in enclosed
// unlit space and inside closed solids are expected; the rest deserve a look in the probes view.
void add_probe_warnings(const DdgiReport& r, std::vector<std::string>& warnings) {
  const int32_t explained = r.enclosed + int32_t(r.cgal_inside);
  const int32_t other = std::max(0, r.inactive - explained);
  if (other == 0 && r.cgal_inactive_outside == 0) return;
  std::string text = std::to_string(r.inactive) + " probes are inactive: " + std::to_string(r.enclosed) +
                     " in enclosed unlit space, " + std::to_string(r.cgal_inside) + " inside closed solids, " +
                     std::to_string(other) + " for another reason (check them in the probes view)";
  if (r.cgal_inactive_outside > 0)
    text += "; " + std::to_string(r.cgal_inactive_outside) +
            " of the inactive ones lie outside every closed solid (open geometry or thin walls: leak risk)";
  warnings.push_back(text);
}

// The largest channel value that 99.5% of the pixels stay under.
float bright_percentile(const PreviewImage& img) {
  std::vector<float> peak;
  peak.reserve(img.rgb.size() / 3);
  for (size_t i = 0; i + 2 < img.rgb.size(); i += 3)
    peak.push_back(std::max({img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]}));
  if (peak.empty()) return 0.f;
  const size_t k = std::min(peak.size() - 1, size_t(double(peak.size()) * 0.995));
  std::nth_element(peak.begin(), peak.begin() + long(k), peak.end());
  return peak[k];
}

// Automatic exposure, lowered where it would clip more than 0.5% of the pixels to white: the
// ACES fit reaches 1 at a scaled value of about 7.2, so the 99.5th percentile goes to 6.
Tonemap report_tonemap(const PreviewImage& img) {
  Tonemap tm;
  const float ev_auto = auto_ev100(img);
  const float bright = bright_percentile(img);
  const float ev_fit = bright > 0.f ? std::log2(bright / (1.2f * 6.f)) : ev_auto;
  if (ev_fit > ev_auto) {
    tm.auto_exposure = false;
    tm.ev100 = ev_fit;
  }
  return tm;
}

// Colour of a patch ratio: blue (half or less) through white (within 10%) to red (twice or more).
uint32_t ratio_colour(double ratio) {
  const double t = std::clamp(std::log2(std::max(ratio, 1e-6)), -1.0, 1.0);  // -1: half, +1: double
  const bool within = std::fabs(ratio - 1.0) <= 0.1;
  const auto c = [](double v) { return uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
  const double r = within ? 1.0 : t > 0 ? 1.0 : 1.0 + t, g = within ? 1.0 : 1.0 - std::fabs(t), b = within ? 1.0 : t < 0 ? 1.0 : 1.0 - t;
  return 0xFF000000u | (c(b) << 16) | (c(g) << 8) | c(r);
}

// The lit view with every patch of the check that its camera sees marked by a square of its colour.
void mark_patches(const PreparedScene& prepared, const PreviewSettings& ps, const ReconstructionError& e,
                  PreviewImage& img) {
  PreviewCamera cam;
  std::string described;
  if (!resolve_camera(prepared.scene(), ps, cam, described)) return;
  img.overlay.assign(size_t(img.width) * img.height, 0u);
  for (const ReconstructionPatch& p : e.samples) {
    if (!(p.reference > 0.f)) continue;
    const kernels::float3 at{p.position[0], p.position[1], p.position[2]};
    float px, py;
    if (!cam.project(at, img.width, img.height, px, py)) continue;
    const kernels::float3 to = at - cam.eye;
    const float dist = kernels::length(to);
    if (prepared.occluded(cam.eye, to * (1.f / dist), 0.f, dist * 0.99f)) continue;  // hidden from this view
    const uint32_t colour = ratio_colour(double(p.baked) / p.reference);
    for (int dy = -6; dy <= 6; ++dy)
      for (int dx = -6; dx <= 6; ++dx) {
        const int x = int(px) + dx, y = int(py) + dy;
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) continue;
        const bool rim = std::abs(dx) == 6 || std::abs(dy) == 6;
        img.overlay[size_t(y) * img.width + x] = rim ? 0xFF000000u : colour;
      }
  }
}

}  // namespace

Status write_report_page(const ReportPageInputs& in, const Context& ctx) {
  const Stopwatch report_time;
  BakeReportInputs page;
  page.scene = in.scene_path;
  page.settings_json = in.result->settings_json;
  if (!in.volumes_json.empty() || !in.quality.empty()) {  // shown with the settings, not in the file's
    nlohmann::json settings = nlohmann::json::parse(page.settings_json);
    if (!in.volumes_json.empty()) settings["volumes"] = nlohmann::json::parse(in.volumes_json);
    if (!in.quality.empty()) settings["quality"] = in.quality;
    page.settings_json = settings.dump();
  }
  page.report = in.report;
  page.result = in.result;
  page.volumes = in.volumes;
  page.warnings = in.warnings;
  page.leak_regions = in.leak_regions;
  page.reconstruction = in.reconstruction;
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
    if (!in.view.empty()) GIBAKE_TRY(check_view_settings(in.view, in.view_fov, ps));
    ps.mode = mode;
    ps.width = 960;
    ps.height = 540;
    ps.probes_depth_tested = true;  // probes behind the floor and walls would hide the room
    PreviewImage img;
    PreviewStats stats;
    GIBAKE_TRY(render_preview(*prepared, &file, ps, quiet, img, &stats));
    float ev = 0.f;
    std::vector<uint8_t> png;
    GIBAKE_TRY(encode_png(img.width, img.height, tonemap_rgb8(img, report_tonemap(img), &ev), png));
    page.images.emplace_back(std::string(preview_mode_name(mode)) + " (" + stats.camera + ", EV100 " +
                                 std::to_string(ev).substr(0, 5) + ")",
                             std::move(png));
    if (mode == PreviewMode::Lit && in.reconstruction) {
      mark_patches(*prepared, ps, *in.reconstruction, img);
      GIBAKE_TRY(encode_png(img.width, img.height, tonemap_rgb8(img, report_tonemap(img)), page.reconstruction_png));
    }
  }
  // The page's own time (its previews are most of it) and the total up to now, on the page itself.
  page.timings = user_timings(in.timings);
  page.timings.emplace_back("report", report_time.seconds());
  page.timings.emplace_back("total", seconds_since(in.bake_start));
  std::vector<std::string> inputs = in.scene->input_files;
  inputs.push_back(in.bake_path);
  return write_bake_report(in.page, page, inputs);
}

}  // namespace gibake::cli
