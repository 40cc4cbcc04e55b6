// `gibake bake scene.gltf --ddgi --out probes.bin [options]` (the subcommand is implied).
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bake/bake_report.h"
#include "bake/ddgi.h"
#include "bake/preview.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "io/bake_file.h"
#include "io/bake_info.h"
#include "io/depfile.h"
#include "io/import.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.0.0"
#endif

namespace gibake::cli {
namespace {

constexpr unsigned kMaxThreads = 1024;  // far beyond any machine; larger values are typos

struct BakeArgs {
  std::string scene;
  std::string out;
  bool ddgi = false;
  unsigned threads = 0;
  std::string progress = "auto";
  float probe_spacing = 0.f;
  std::string probe_counts, grid_min, grid_max;
  float padding = 0.f;
  std::string gather = "path";
  uint32_t rays = 256, max_rays = 0;
  float target_error = 0.f;
  uint64_t seed = 0;
  int bounces = 4;
  float energy_conservation = 1.f;
  int sh_order = 2;
  std::string light_sampling = "all";
  std::string sky;
  std::string sky_hdr;
  float sky_hdr_scale = 1.f;
  std::vector<std::string> suns;
  std::string relocate = "on";
  std::string closed_mesh_check = "on";
  float blend_cutoff = 0.5f;
  int max_atlas_width = 16384;
  uint64_t max_probes = uint64_t(1) << 21;
  std::string depfile;
  bool metadata_timings = false;
  std::string sh_format = "f32";
  std::string atlas_format = "auto";
  std::string report;  // --report report.html
};

bool parse_precision(const std::string& text, FloatPrecision& out) {
  if (text == "auto") out = FloatPrecision::Auto;
  else if (text == "f16") out = FloatPrecision::Half;
  else if (text == "f32") out = FloatPrecision::Full;
  else return false;
  return true;
}

Status bad_arg(const std::string& option, const std::string& what) {
  return Status::error(ExitCode::BadArguments, "", option, what);
}

// "a,b,c" -> exactly n finite numbers.
bool parse_list(const std::string& text, size_t n, std::vector<double>& out) {
  out.clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) return false;
      out.push_back(v);
    } catch (...) {
      return false;
    }
  }
  return out.size() == n;
}

Status parse_vec3(const std::string& option, const std::string& text, std::array<float, 3>& out) {
  std::vector<double> v;
  if (!parse_list(text, 3, v)) return bad_arg(option, "expected three numbers x,y,z, got '" + text + "'");
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(v[i]);
  return Status::ok();
}

// dx,dy,dz:lux[:r,g,b]
Status parse_sun(const std::string& text, SunLight& sun) {
  const size_t c1 = text.find(':');
  if (c1 == std::string::npos) return bad_arg("--sun", "expected dx,dy,dz:lux[:r,g,b], got '" + text + "'");
  const size_t c2 = text.find(':', c1 + 1);
  GIBAKE_TRY(parse_vec3("--sun", text.substr(0, c1), sun.direction));
  std::vector<double> lux;
  if (!parse_list(text.substr(c1 + 1, c2 == std::string::npos ? std::string::npos : c2 - c1 - 1), 1, lux) ||
      lux[0] < 0)
    return bad_arg("--sun", "illuminance (lux) must be a non-negative number in '" + text + "'");
  sun.lux = static_cast<float>(lux[0]);
  if (c2 != std::string::npos) GIBAKE_TRY(parse_vec3("--sun", text.substr(c2 + 1), sun.color));
  return Status::ok();
}

Status to_settings(const BakeArgs& a, DdgiSettings& s) {
  s.grid.padding = a.padding;
  s.grid.spacing = a.probe_spacing;
  s.grid.max_probes = a.max_probes;
  if (!a.probe_counts.empty()) {
    std::vector<double> v;
    if (!parse_list(a.probe_counts, 3, v)) return bad_arg("--probe-counts", "expected X,Y,Z");
    for (int i = 0; i < 3; ++i) {
      if (v[i] < 1 || v[i] > 1e6 || v[i] != std::floor(v[i]))
        return bad_arg("--probe-counts", "counts must be positive integers");
      s.grid.counts[i] = static_cast<int32_t>(v[i]);
    }
    if (a.probe_spacing > 0.f) return bad_arg("--probe-spacing", "give either --probe-spacing or --probe-counts");
  }
  if (!a.grid_min.empty() || !a.grid_max.empty()) {
    if (a.grid_min.empty() || a.grid_max.empty() || a.probe_counts.empty())
      return bad_arg("--grid-min", "--grid-min, --grid-max and --probe-counts go together");
    GIBAKE_TRY(parse_vec3("--grid-min", a.grid_min, s.grid.grid_min));
    GIBAKE_TRY(parse_vec3("--grid-max", a.grid_max, s.grid.grid_max));
    s.grid.explicit_bounds = true;
  }
  s.rays = a.rays;
  s.max_rays = a.max_rays;
  s.target_error = a.target_error;
  s.seed = a.seed;
  s.bounces = a.bounces;
  if (a.gather == "path") s.gather = Gather::Path;
  else if (a.gather == "probes") s.gather = Gather::Probes;
  else return bad_arg("--gather", "expected 'path' or 'probes'");
  s.energy_conservation = a.energy_conservation;
  s.sh_order = a.sh_order;
  if (a.light_sampling == "all") s.light_sampling = LightSampling::All;
  else if (a.light_sampling == "random") s.light_sampling = LightSampling::Random;
  else return bad_arg("--light-sampling", "expected 'all' or 'random'");
  if (!a.sky.empty()) GIBAKE_TRY(parse_vec3("--sky", a.sky, s.sky));
  s.sky_hdr = a.sky_hdr;
  s.sky_hdr_scale = a.sky_hdr_scale;
  s.blend_cutoff = a.blend_cutoff;
  s.max_atlas_width = a.max_atlas_width;
  for (const std::string& text : a.suns) {
    SunLight sun;
    GIBAKE_TRY(parse_sun(text, sun));
    s.suns.push_back(sun);
  }
  if (a.relocate == "on") s.relocate = true;
  else if (a.relocate == "off") s.relocate = false;
  else return bad_arg("--relocate", "expected 'on' or 'off'");
  if (a.closed_mesh_check == "on") s.cgal_check = true;
  else if (a.closed_mesh_check == "off") s.cgal_check = false;
  else return bad_arg("--closed-mesh-check", "expected 'on' or 'off'");
  return validate_ddgi_settings(s);
}

long peak_rss_kib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;  // KiB on Linux
}

// --report: the bake's page with lit and probes previews of the file just written.
Status write_report(const BakeArgs& a, const Scene& scene, const DdgiResult& result, const DdgiReport& report,
                    double import_s, double write_s, const std::vector<std::string>& warnings, const Context& ctx) {
  BakeReportInputs in;
  in.scene = a.scene;
  in.settings_json = result.settings_json;
  in.timings.emplace_back("import", import_s);
  for (const auto& st : report.stage_seconds) in.timings.push_back(st);
  in.timings.emplace_back("write", write_s);
  in.report = &report;
  in.result = &result;
  in.warnings = warnings;
  if (report.cgal_inactive_outside > 0)
    in.warnings.push_back(std::to_string(report.cgal_inactive_outside) +
                          " inactive probes lie outside every closed solid (open geometry or thin walls: leak risk)");
  if (report.inactive > report.enclosed + int32_t(report.cgal_inside))
    in.warnings.push_back(std::to_string(report.inactive - report.enclosed) +
                          " probes are inactive without being enclosed: check them in the probes view");
  loader::BakeFile file;
  GIBAKE_TRY(open_bake_file(a.out, file));
  Context quiet = ctx;
  quiet.progress = nullptr;
  std::unique_ptr<PreparedScene> prepared;
  PrepareOptions po;
  po.blend_cutoff = a.blend_cutoff;
  GIBAKE_TRY(PreparedScene::create(scene, quiet, prepared, po));
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
    in.images.emplace_back(std::string(preview_mode_name(mode)) + " (" + stats.camera + ", EV100 " +
                               std::to_string(ev).substr(0, 5) + ")",
                           std::move(png));
  }
  std::vector<std::string> inputs = scene.input_files;
  inputs.push_back(a.out);
  return write_bake_report(a.report, in, inputs);
}

int run_bake(const BakeArgs& a) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (!a.ddgi)
    return report_error(bad_arg("bake", "nothing to bake: add --ddgi (e.g. gibake " +
                                            (a.scene.empty() ? std::string("scene.gltf") : a.scene) +
                                            " --ddgi --out probes.bin)"));
  if (a.out.empty()) return report_error(bad_arg("--out", "an output file is required (--out probes.bin)"));
  ProgressMode mode;
  if (!parse_progress_mode(a.progress, mode))
    return report_error(bad_arg("--progress", "expected auto, bar, lines or json"));
  DdgiSettings settings;
  if (Status st = to_settings(a, settings); !st) return report_error(st);
  BakeFileOptions file_options;
  if (!parse_precision(a.sh_format, file_options.sh))
    return report_error(bad_arg("--sh-format", "expected f32, f16 or auto"));
  if (!parse_precision(a.atlas_format, file_options.atlas))
    return report_error(bad_arg("--atlas-format", "expected auto, f16 or f32"));

  auto progress = std::make_shared<Progress>(mode);
  Context ctx;
  ctx.threads = a.threads;
  auto warnings = std::make_shared<std::vector<std::string>>();  // for --report
  ctx.warn = [progress, warnings](const std::string& m) {
    warnings->push_back(m);
    progress->clear();
    if (progress->mode() == ProgressMode::Json) progress->note("warning", m);
    else print_warning(m);
  };
  ctx.info = [progress](const std::string& m) {
    progress->clear();
    if (progress->mode() == ProgressMode::Json) progress->note("info", m);
    else std::fprintf(stderr, "gibake: %s\n", m.c_str());
  };
  ctx.progress = [progress](const std::string& stage, double done, double total) { progress->update(stage, done, total); };

  Scene scene;
  const auto t_import = Clock::now();
  if (Status st = import_scene(a.scene, ImportOptions{}, ctx, scene); !st) {
    progress->clear();
    return report_error(st);
  }
  const double import_s = std::chrono::duration<double>(Clock::now() - t_import).count();

  DdgiResult result;
  DdgiReport report;
  if (Status st = bake_ddgi(scene, settings, ctx, result, report); !st) {
    progress->clear();
    return report_error(st);
  }

  nlohmann::json timings{{"import", import_s}};
  for (const auto& [stage, sec] : report.stage_seconds) timings[stage] = sec;
  timings["bake_total"] = report.seconds_total;
  nlohmann::json meta{{"tool", "gibake"},
                      {"version", GIBAKE_VERSION},
                      {"scene", a.scene},
                      {"settings", nlohmann::json::parse(result.settings_json)},

                      {"probes", {{"total", report.probes}, {"active", report.active}, {"inactive", report.inactive},
                                  {"enclosed", report.enclosed}, {"sky_only", report.sky_only},
                                  {"relocated", report.relocated}}},
                      {"closed_mesh_check", {{"checked", report.cgal_checked}, {"inside", report.cgal_inside},
                                             {"inside_but_active", report.cgal_disagreements},
                                             {"inactive_outside_closed", report.cgal_inactive_outside}}},
                      {"rays", {{"primary", report.primary_rays}, {"bounce", report.bounce_rays},
                                {"shadow", report.shadow_rays},
                                {"relocation", report.relocation_rays}}}};

  // Timings and the thread count change from run to run; the file stays byte-identical for the
  // same inputs and seed unless they are asked for.
  if (a.metadata_timings) {
    meta["threads"] = a.threads;
    meta["timings_s"] = timings;
  }
  const auto t_write = Clock::now();
  uint64_t hash = 0;
  if (Status st = hash_inputs(scene.input_files, result.settings_json, hash); !st) {
    progress->clear();
    return report_error(st);
  }
  BakeOutputs outputs;
  outputs.ddgi = &result;
  outputs.metadata_json = meta.dump();
  outputs.input_hash = hash;
  file_options.warn = ctx.warn;
  if (Status st = write_bake_file(a.out, outputs, file_options, scene.input_files); !st) {
    progress->clear();
    return report_error(st);
  }
  if (!a.depfile.empty()) {
    if (Status st = write_depfile(a.depfile, a.out, scene.input_files); !st) {
      progress->clear();
      return report_error(st);
    }
  }
  const double write_s = std::chrono::duration<double>(Clock::now() - t_write).count();
  if (!a.report.empty()) {
    if (Status st = write_report(a, scene, result, report, import_s, write_s, *warnings, ctx); !st) {
      progress->clear();
      return report_error(st);
    }
  }
  const double total_s = std::chrono::duration<double>(Clock::now() - t0).count();

  const double mrays = report.seconds_total > 0 ? report.total_rays() / report.seconds_total / 1e6 : 0.0;
  progress->clear();
  if (progress->mode() == ProgressMode::Json) {
    nlohmann::json j{{"event", "summary"}, {"out", a.out}, {"probes", meta["probes"]}, {"rays", meta["rays"]},
                     {"mrays_per_s", mrays}, {"timings_s", timings}, {"write_s", write_s}, {"total_s", total_s},
                     {"peak_rss_mib", peak_rss_kib() / 1024.0}};
    std::fprintf(stderr, "%s\n", j.dump().c_str());
  } else {
    std::fprintf(stderr, "gibake: wrote %s\n", a.out.c_str());
    std::fprintf(stderr, "  probes: %d (%d active, %d inactive, %d relocated), grid %dx%dx%d\n", report.probes,
                 report.active, report.inactive, report.relocated, result.desc.counts[0], result.desc.counts[1],
                 result.desc.counts[2]);
    if (report.enclosed || report.sky_only)
      std::fprintf(stderr, "  of which %d inactive in enclosed unlit space, %d see only sky (state sky-only)\n",
                   report.enclosed, report.sky_only);
    std::fprintf(stderr, "  rays: %llu (%llu primary, %llu bounce, %llu shadow, %llu relocation), %.2f Mrays/s\n",
                 static_cast<unsigned long long>(report.total_rays()),
                 static_cast<unsigned long long>(report.primary_rays),
                 static_cast<unsigned long long>(report.bounce_rays),
                 static_cast<unsigned long long>(report.shadow_rays),
                 static_cast<unsigned long long>(report.relocation_rays), mrays);
    std::string stages = "  seconds: import " + std::to_string(import_s).substr(0, 6);
    for (const auto& [stage, sec] : report.stage_seconds) stages += ", " + stage + " " + std::to_string(sec).substr(0, 6);
    stages += ", write " + std::to_string(write_s).substr(0, 6) + ", total " + std::to_string(total_s).substr(0, 6);
    std::fprintf(stderr, "%s\n", stages.c_str());
    std::fprintf(stderr, "  peak memory: %.1f MiB\n", peak_rss_kib() / 1024.0);
    if (report.cgal_checked)
      std::fprintf(stderr,
                   "  closed-mesh check (CGAL): %u probes inside closed solids, %u of them left active by the ray "
                   "test; %u inactive probes outside every closed solid (open geometry)\n",
                   report.cgal_inside, report.cgal_disagreements, report.cgal_inactive_outside);
  }
  return 0;
}

}  // namespace

void add_bake_command(CLI::App& app, CliState& state) {
  auto args = std::make_shared<BakeArgs>();
  CLI::App* sub = app.add_subcommand("bake", "bake global illumination for a glTF scene");
  sub->add_option("scene", args->scene, "scene file (.gltf or .glb)")->required();
  sub->add_flag("--ddgi", args->ddgi, "bake DDGI probes");
  sub->add_option("--out,-o", args->out, "output bake file");
  sub->add_option("--threads", args->threads, "worker threads (0 = all; results do not depend on it)")
      ->check(CLI::Range(0u, kMaxThreads));
  sub->add_option("--progress", args->progress, "auto|bar|lines|json (stderr)");
  sub->add_option("--probe-spacing", args->probe_spacing,
                  "probe spacing in metres (default: longest side / 16, within 0.25..4 m, at most 32768 probes)");
  sub->add_option("--probe-counts", args->probe_counts, "X,Y,Z probes per axis");
  sub->add_option("--grid-min", args->grid_min, "x,y,z of probe (0,0,0) (with --grid-max, --probe-counts)");
  sub->add_option("--grid-max", args->grid_max, "x,y,z of the last probe");
  sub->add_option("--grid-padding", args->padding, "metres added around the scene bounds (default 0)");
  sub->add_option("--max-probes", args->max_probes, "refuse grids with more probes (default 2097152)");
  sub->add_option("--rays", args->rays, "rays per probe per batch (default 256)");
  sub->add_option("--max-rays", args->max_rays, "per-probe ray cap with --target-error (default 16 x --rays)");
  sub->add_option("--target-error", args->target_error, "stop a probe at this relative standard error");
  sub->add_option("--seed", args->seed, "random seed (default 0)");
  sub->add_option("--gather", args->gather,
                  "path|probes: light at ray hits from continued paths (converges to the path-traced truth) or "
                  "read back from the previous pass's probes (fast runtime approximation) (default path)");
  sub->add_option("--bounces", args->bounces, "indirect bounces: path vertices after the first hit (default 4)");
  sub->add_option("--energy-conservation", args->energy_conservation, "indirect scale per bounce (default 1)");
  sub->add_option("--sh-order", args->sh_order, "1 or 2 (default 2)");
  sub->add_option("--light-sampling", args->light_sampling, "all|random (default all)");
  sub->add_option("--sky", args->sky, "constant sky radiance r,g,b in cd/m^2 (default black)");
  sub->add_option("--sky-hdr", args->sky_hdr, "equirect EXR sky (+Y up, centre column looks along -Z)");
  sub->add_option("--sky-hdr-scale", args->sky_hdr_scale, "multiplier for --sky-hdr values (default 1)");
  sub->add_option("--sun", args->suns,
                  "directional light dx,dy,dz:lux[:r,g,b]; d is the direction the light travels (0,-1,0 = from "
                  "straight above); repeatable");
  sub->add_option("--relocate", args->relocate, "on|off (default on)");
  sub->add_option("--closed-mesh-check", args->closed_mesh_check,
                  "on|off: cross-check inactive probes against closed meshes with CGAL (default on)");
  sub->add_option("--blend-cutoff", args->blend_cutoff,
                  "alpha cutoff for alphaMode BLEND materials, which are traced as MASK (default 0.5; 0 = opaque)");
  sub->add_option("--max-atlas-width", args->max_atlas_width,
                  "widest atlas in texels; Y-planes of tiles wrap onto more rows to stay within it (default 16384)");
  sub->add_option("--depfile", args->depfile,
                  "also write a Makefile-style depfile listing the scene and every buffer/image read");
  sub->add_flag("--metadata-timings", args->metadata_timings,
                "record timings and the thread count in the file's metadata (the file then differs "
                "from run to run)");
  sub->add_option("--sh-format", args->sh_format, "f32|f16|auto: SH coefficient storage (default f32)");
  sub->add_option("--atlas-format", args->atlas_format,
                  "auto|f16|f32: atlas storage; auto = f16 when every value fits (default auto)");
  sub->add_option("--report", args->report,
                  "also write a self-contained HTML report (settings, timings, probe statistics, warnings, previews)");
  sub->callback([&state, args] { state.run = [args] { return run_bake(*args); }; });
}

}  // namespace gibake::cli
