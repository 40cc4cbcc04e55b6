// The bake report page (see bake_report.h).
#include "bake/preview/bake_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "bake/preview/preview.h"
#include "io/bakefile/json_text.h"
#include "io/output/bake_atomic.h"

namespace gibake {
namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '&': o += "&amp;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string num(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// Histogram of per-probe relative standard error (active and sky-only probes), inline SVG.
std::string error_histogram_svg(const DdgiResult& r) {
  std::vector<float> errs;
  for (size_t i = 0; i < r.stats.size() && i < r.states.size(); ++i)
    if (r.states[i] != ProbeState::Inactive && std::isfinite(r.stats[i].relative_error))
      errs.push_back(r.stats[i].relative_error);
  if (errs.empty()) return "<p>No active probes.</p>";
  constexpr int kBins = 20;
  float hi = *std::max_element(errs.begin(), errs.end());
  if (!(hi > 0.f)) hi = 1.f;
  std::vector<int> bins(kBins, 0);
  for (float e : errs) bins[size_t(std::min(kBins - 1, int(e / hi * kBins)))]++;
  const int peak = *std::max_element(bins.begin(), bins.end());
  const int W = 600, H = 200, pad = 30;
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(W) + "\" height=\"" +
                    std::to_string(H + 2 * pad) + "\" role=\"img\" aria-label=\"estimated error histogram\">";
  const double bw = double(W - 2 * pad) / kBins;
  for (int b = 0; b < kBins; ++b) {
    const double h = peak ? double(bins[size_t(b)]) / peak * H : 0.0;
    svg += "<rect x=\"" + num(pad + b * bw, 6) + "\" y=\"" + num(pad + H - h, 6) + "\" width=\"" + num(bw - 1, 6) +
           "\" height=\"" + num(h, 6) + "\" fill=\"#4a7fb5\"><title>" + num(double(b) / kBins * hi) + " .. " +
           num(double(b + 1) / kBins * hi) + ": " + std::to_string(bins[size_t(b)]) + " probes</title></rect>";
  }
  svg += "<line x1=\"" + std::to_string(pad) + "\" y1=\"" + std::to_string(pad + H) + "\" x2=\"" +
         std::to_string(W - pad) + "\" y2=\"" + std::to_string(pad + H) + "\" stroke=\"#333\"/>";
  svg += "<text x=\"" + std::to_string(pad) + "\" y=\"" + std::to_string(H + 2 * pad - 8) +
         "\" font-size=\"12\">0</text><text x=\"" + std::to_string(W - pad - 60) + "\" y=\"" +
         std::to_string(H + 2 * pad - 8) + "\" font-size=\"12\">" + num(hi) + "</text>";
  svg += "<text x=\"" + std::to_string(pad) + "\" y=\"18\" font-size=\"12\">peak " + std::to_string(peak) +
         " probes per bin; relative standard error of irradiance</text></svg>";
  return svg;
}

// The reconstruction check: its summary, where it was measured (the lit view with the patches it
// sees, coloured by ratio), and the worst patches.
std::string reconstruction_html(const ReconstructionError& e, const std::vector<uint8_t>& png) {
  std::string h = "<h2>Reconstruction error</h2><p>" + esc(reconstruction_summary(e)) +
                  ". Each patch is 4x4 surface points shaded as the lit preview shades a pixel, with the "
                  "irradiance the loader's sampler reconstructs from this file and with path-traced irradiance; "
                  "the ratio is baked / reference.</p>\n";
  if (!png.empty())
    h += "<figure><img alt=\"patches\" src=\"data:image/png;base64," + base64_encode(png) +
         "\"><figcaption>patches seen from the report's camera: blue darker than the truth, white within 10%, red "
         "brighter (saturating at 2x)</figcaption></figure>\n";
  std::vector<const ReconstructionPatch*> worst;
  for (const ReconstructionPatch& p : e.samples)
    if (p.reference > 0.f) worst.push_back(&p);
  auto error = [](const ReconstructionPatch* p) { return std::fabs(std::log(std::max(1e-6, double(p->baked) / p->reference))); };
  std::stable_sort(worst.begin(), worst.end(), [&](auto* a, auto* b) { return error(a) > error(b); });
  if (worst.size() > 10) worst.resize(10);
  h += "<h3>Worst patches</h3><table><tr><th>position (m)</th><th>normal</th><th>baked / reference</th></tr>";
  for (const ReconstructionPatch* p : worst)
    h += "<tr><td>" + num(p->position[0], 4) + ", " + num(p->position[1], 4) + ", " + num(p->position[2], 4) +
         "</td><td>" + num(p->normal[0], 3) + ", " + num(p->normal[1], 3) + ", " + num(p->normal[2], 3) +
         "</td><td class=\"n\">" + num(double(p->baked) / p->reference, 3) + "</td></tr>";
  return h + "</table>\n";
}

const char* report_head() {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
         "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; "
         "style-src 'unsafe-inline'\"><title>gibake bake report</title><style>"
         "body{font-family:sans-serif;margin:2em;max-width:1400px}table{border-collapse:collapse}"
         "td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}td.n{text-align:right}"
         "img{max-width:100%;border:1px solid #888}figure{display:inline-block;margin:0 1em 1em 0}"
         ".warn{color:#a40}pre{background:#f4f4f4;padding:1em;overflow:auto}</style></head><body>\n";
}

// Each volume's line (volumes.h volume_line), probe counts by state and rays, and their totals.
std::string volumes_html(const std::vector<BakedVolume>& volumes) {
  std::string h = "<h2>Probe volumes</h2><p>" + std::to_string(volumes.size()) +
                  " volumes; the grid, probe and ray sections below are volume 0's.</p><table><tr><th>volume</th>"
                  "<th>probes</th><th>active</th><th>inactive</th><th>sky only</th><th>rays</th></tr>";
  auto row = [&h](const std::string& what, double probes, double active, double inactive, double sky, double rays) {
    h += "<tr><td>" + esc(what) + "</td>";
    for (double v : {probes, active, inactive, sky, rays}) h += "<td class=\"n\">" + num(v, 15) + "</td>";
    h += "</tr>";
  };
  double sum[5] = {0, 0, 0, 0, 0};
  for (size_t i = 0; i < volumes.size(); ++i) {
    const DdgiReport& r = volumes[i].report;
    const double v[5] = {double(r.probes), double(r.active), double(r.inactive), double(r.sky_only),
                         double(r.total_rays())};
    row(volume_line(i, volumes[i]), v[0], v[1], v[2], v[3], v[4]);
    for (int k = 0; k < 5; ++k) sum[k] += v[k];
  }
  row("all volumes", sum[0], sum[1], sum[2], sum[3], sum[4]);
  return h + "</table>\n";
}

std::string grid_html(const DdgiVolumeDesc& d, const std::string& which) {
  auto v3 = [](const std::array<float, 3>& v) { return num(v[0], 4) + ", " + num(v[1], 4) + ", " + num(v[2], 4); };
  return "<h2>Probe grid" + which + "</h2><p>" + std::to_string(d.counts[0]) + " x " + std::to_string(d.counts[1]) +
         " x " + std::to_string(d.counts[2]) + " = " + std::to_string(d.probe_count()) + " probes, spacing " +
         num(d.spacing[0], 4) + " x " + num(d.spacing[1], 4) + " x " + num(d.spacing[2], 4) + " m, from (" +
         v3(d.grid_min) + ") to (" + v3(d.grid_max) + ") m.</p>\n";
}

std::string probe_counts_html(const DdgiReport& r, const std::string& which) {
  std::string h = "<h2>Probes" + which + "</h2><table><tr><th>state</th><th>count</th></tr>";
  auto row = [&h](const std::string& k, double v) {
    h += "<tr><td>" + esc(k) + "</td><td class=\"n\">" + num(v, 12) + "</td></tr>";
  };
  row("total", r.probes);
  row("active", r.active);
  row("inactive", r.inactive);
  row("of which enclosed (unlit, unreachable from outside)", r.enclosed);
  row("sky only", r.sky_only);
  row("relocated", r.relocated);
  h += "</table>\n<h3>Rays</h3><table>";
  row("primary", double(r.primary_rays));
  row("bounce", double(r.bounce_rays));
  row("shadow", double(r.shadow_rays));
  row("relocation", double(r.relocation_rays));
  row("total", double(r.total_rays()));
  return h + "</table>\n";
}

// The rays a probe took (min, mean, max) and the histogram of their estimated error.
std::string probe_rays_html(const DdgiResult& result, const DdgiReport* report) {
  const auto& st = result.stats;
  uint32_t lo = UINT32_MAX, hi = 0;
  double sum = 0;
  for (const auto& p : st) {
    lo = std::min(lo, p.rays);
    hi = std::max(hi, p.rays);
    sum += p.rays;
  }
  // The per-probe count includes relocation's rays: say how many, so that a minimum above --rays reads right.
  const double reloc = report && report->probes > 0 ? double(report->relocation_rays) / report->probes : 0.0;
  return "<p>Rays per probe, relocation rays included (" + num(reloc, 5) + " per probe): min " + std::to_string(lo) +
         ", mean " + num(sum / double(st.size()), 5) + ", max " + std::to_string(hi) +
         ".</p>\n<h3>Estimated error (active and sky-only probes)</h3>\n" + error_histogram_svg(result) + "\n";
}

std::string timings_html(const std::vector<std::pair<std::string, double>>& timings) {
  std::string h = "<h2>Timings</h2><table><tr><th>stage</th><th>seconds</th></tr>";
  for (const auto& [stage, sec] : timings)
    h += "<tr><td>" + esc(stage) + "</td><td class=\"n\">" + num(sec, 4) + "</td></tr>";
  return h + "</table>\n";
}

std::string warnings_html(const std::vector<std::string>& warnings) {
  if (warnings.empty()) return "<h2>Warnings</h2><p>None.</p>";
  std::string h = "<h2>Warnings</h2><ul>";
  for (const auto& w : warnings) h += "<li class=\"warn\">" + esc(w) + "</li>";
  return h + "</ul>";
}

std::string leaks_html(const std::vector<std::string>& regions) {
  if (regions.empty()) return "\n<h2>Leak audit</h2><p>No thin wall between lit and unlit space.</p>";
  std::string h =
      "\n<h2>Leak audit</h2><p>Every thin-wall region between lit and unlit space; only those that active "
      "probes blend across were warned about.</p><ol>";
  for (const auto& line : regions) h += "<li>" + esc(line) + "</li>";
  return h + "</ol>";
}

std::string settings_html(const std::string& settings_json) {
  std::string settings = settings_json;
  const nlohmann::json j = nlohmann::json::parse(settings, nullptr, false);
  if (!j.is_discarded()) settings = settings_for_reading(j).dump(2);
  return "\n<h2>Settings</h2><pre>" + esc(settings) + "</pre>\n";
}

}  // namespace

std::string bake_report_html(const BakeReportInputs& in) {
  std::string h = report_head();
  h += "<h1>gibake bake report</h1><p>Scene: <code>" + esc(in.scene) + "</code></p>\n";
  h += "<h2>Previews</h2>\n";
  for (const auto& [caption, png] : in.images)
    h += "<figure><img alt=\"" + esc(caption) + "\" src=\"data:image/png;base64," + base64_encode(png) +
         "\"><figcaption>" + esc(caption) + "</figcaption></figure>\n";
  const bool several = in.volumes && in.volumes->size() > 1;
  const std::string which = several ? " (volume 0)" : "";
  if (several) h += volumes_html(*in.volumes);
  if (in.result) h += grid_html(in.result->desc, which);
  if (in.report) h += probe_counts_html(*in.report, which);
  if (in.result && !in.result->stats.empty()) h += probe_rays_html(*in.result, in.report);
  if (in.reconstruction) h += reconstruction_html(*in.reconstruction, in.reconstruction_png);
  h += timings_html(in.timings);
  h += warnings_html(in.warnings);
  h += leaks_html(in.leak_regions);
  h += settings_html(in.settings_json);
  return h + "</body></html>\n";
}

Status write_bake_report(const std::string& path, const BakeReportInputs& in, const std::vector<std::string>& inputs) {
  const std::string html = bake_report_html(in);
  return write_file_atomic(path, html.data(), html.size(), inputs);
}

}  // namespace gibake
