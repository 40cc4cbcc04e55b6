// `gibake verify`: orchestration, sanity checks and the report (see bake_verify.h).
#include "io/bakefile/bake_verify.h"
#include "io/bakefile/vxgi_report.h"

#include <cmath>
#include <limits>

#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_shard.h"

namespace gibake {
namespace verify_detail {

using nlohmann::json;

void add(VerifyReport& report, std::string name, std::string status, std::string message, json details) {
  report.checks.push_back({std::move(name), std::move(status), std::move(message), std::move(details)});
}

const std::vector<loader::Vec3>& directions() {
  static const std::vector<loader::Vec3> dirs = [] {
    std::vector<loader::Vec3> out;
    const int n = 64;
    const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / n;
      const double r = std::sqrt(1.0 - z * z);
      out.push_back({float(r * std::cos(golden * i)), float(r * std::sin(golden * i)), float(z)});
    }
    return out;
  }();
  return dirs;
}

loader::Rgb sh_irradiance_raw(const loader::DdgiVolume& v, uint32_t probe, const loader::Vec3& n) {
  const float pi = 3.14159265358979323846f;
  const float x = n[0], y = n[1], z = n[2];
  const float basis[9] = {pi * 0.282095f,           2.f * pi / 3.f * 0.488603f * y,
                          2.f * pi / 3.f * 0.488603f * z, 2.f * pi / 3.f * 0.488603f * x,
                          pi / 4.f * 1.092548f * x * y,   pi / 4.f * 1.092548f * y * z,
                          pi / 4.f * 0.315392f * (3.f * z * z - 1.f), pi / 4.f * 1.092548f * x * z,
                          pi / 4.f * 0.546274f * (x * x - y * y)};
  loader::Rgb e{0.f, 0.f, 0.f};
  for (uint32_t c = 0; c < v.sh_coefficients() && c < 9; ++c)
    for (uint32_t k = 0; k < 3; ++k) e[k] += basis[c] * v.sh(probe, c, k);
  return e;
}

namespace {

// Counts the values that are not finite, or so large that a sampler's weighted sums of them
// overflow a float (a finite value near its limit reads back as infinite light), and names the
// first one's place. `where` makes the place's text only for that one: a string for every value
// would cost many times the scan itself.
struct FiniteScan {
  static constexpr float kLargest = 1e36f;
  uint64_t bad = 0;
  std::string first;
  template <class Where>
  void check(float value, const Where& where) {
    if (std::fabs(value) <= kLargest) return;
    if (bad++ == 0) first = where();
  }
};

// Every value of the volume, or with `sh_only` its SH alone (the light every other light value is
// made from: where light overflows, its SH does).
void scan_volume(const loader::DdgiVolume& v, size_t vi, FiniteScan& scan, bool sh_only = false) {
  const std::string prefix = "ddgi[" + std::to_string(vi) + "].";
  const gibake_ddgi_volume& d = v.desc();
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    for (uint32_t c = 0; c < v.sh_coefficients(); ++c)
      for (uint32_t k = 0; k < 3; ++k)
        scan.check(v.sh(p, c, k), [&] { return prefix + "sh probe " + std::to_string(p); });
    if (sh_only) continue;
    const loader::Vec3 o = v.offset(p);
    for (float f : o) scan.check(f, [&] { return prefix + "offsets probe " + std::to_string(p); });
    const gibake_probe_stats st = v.stats(p);
    for (float f : {st.relative_error, st.nearest_front, st.backface_fraction})
      scan.check(f, [&] { return prefix + "stats probe " + std::to_string(p); });
  }
  if (sh_only) return;
  for (uint32_t y = 0; y < d.irradiance_height; ++y)
    for (uint32_t x = 0; x < d.irradiance_width; ++x)
      for (float f : v.irradiance_texel(x, y))
        scan.check(f,
                   [&] { return prefix + "irradiance texel (" + std::to_string(x) + "," + std::to_string(y) + ")"; });
  for (uint32_t y = 0; y < d.depth_height; ++y)
    for (uint32_t x = 0; x < d.depth_width; ++x)
      for (float f : v.depth_texel(x, y))
        scan.check(f, [&] { return prefix + "depth texel (" + std::to_string(x) + "," + std::to_string(y) + ")"; });
}

void check_negative(const loader::DdgiVolume& v, size_t vi, VerifyReport& report) {
  const gibake_ddgi_volume& d = v.desc();
  float worst = 0.f;
  std::string where;
  for (uint32_t y = 0; y < d.irradiance_height; ++y)
    for (uint32_t x = 0; x < d.irradiance_width; ++x) {
      const std::array<float, 4> t = v.irradiance_texel(x, y);
      for (int k = 0; k < 3; ++k)
        if (t[k] < worst) {
          worst = t[k];
          where = "irradiance texel (" + std::to_string(x) + "," + std::to_string(y) + ")";
        }
    }
  for (uint32_t y = 0; y < d.depth_height; ++y)
    for (uint32_t x = 0; x < d.depth_width; ++x) {
      const std::array<float, 2> t = v.depth_texel(x, y);
      for (float f : t)
        if (f < worst) {
          worst = f;
          where = "depth texel (" + std::to_string(x) + "," + std::to_string(y) + ")";
        }
    }
  const std::string name = "ddgi[" + std::to_string(vi) + "].nonnegative";
  if (worst < 0.f)
    add(report, name, "fail", "negative atlas value " + std::to_string(worst) + " at " + where,
        {{"min", double(worst)}, {"where", where}});
  else
    add(report, name, "pass", "no negative irradiance or depth texels");
}

// Worst negative SH irradiance relative to the probe's peak, over the fixed directions.
void check_ringing(const loader::DdgiVolume& v, size_t vi, VerifyReport& report) {
  double worst = 0.0;
  int64_t worst_probe = -1;
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    if (v.state(p) == GIBAKE_PROBE_INACTIVE) continue;
    float lo = 0.f, peak = 0.f;
    for (const loader::Vec3& n : directions()) {
      const loader::Rgb e = sh_irradiance_raw(v, p, n);
      for (float f : e) {
        lo = std::min(lo, f);
        peak = std::max(peak, f);
      }
    }
    if (lo < 0.f) {
      const double ratio = peak > 0.f ? double(lo) / double(peak) : -1.0;
      if (ratio < worst) {
        worst = ratio;
        worst_probe = p;
      }
    }
  }
  const std::string name = "ddgi[" + std::to_string(vi) + "].sh_ringing";
  json details{{"worst_negative_relative", worst}, {"probe", worst_probe}, {"directions", directions().size()}};
  if (worst < -0.1)
    add(report, name, "warn", "probe " + std::to_string(worst_probe) + " SH irradiance dips to " +
                                  std::to_string(worst) + " of its peak (ringing)", details);
  else
    add(report, name, "pass", "worst negative SH irradiance " + std::to_string(worst) + " of peak", details);
}

// Every probe state is one gibake_probe_state defines (format.h): a sampler takes any other value
// for a probe to sample, so an undefined state would light a scene without anyone knowing.
void check_states(const loader::DdgiVolume& v, size_t vi, VerifyReport& report) {
  uint64_t bad = 0;
  int64_t first_probe = -1;
  uint32_t first_state = 0;
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    const uint32_t state = v.state(p);
    if (state == GIBAKE_PROBE_ACTIVE || state == GIBAKE_PROBE_INACTIVE || state == GIBAKE_PROBE_SKY_ONLY) continue;
    if (bad++ == 0) {
      first_probe = p;
      first_state = state;
    }
  }
  const std::string name = "ddgi[" + std::to_string(vi) + "].states";
  const char* defined = "0 (active), 1 (inactive) or 2 (sky only)";
  json details{{"count", bad}, {"probe", first_probe}};
  if (bad) {
    details["state"] = first_state;
    add(report, name, "fail",
        "probe " + std::to_string(first_probe) + " has state " + std::to_string(first_state) + ", not " + defined +
            " (" + std::to_string(bad) + " of " + std::to_string(v.probe_count()) + " probes undefined)",
        details);
  } else {
    add(report, name, "pass", std::string("every probe state is ") + defined, details);
  }
}

void scan_lpv(const loader::LpvCascade& c, FiniteScan& scan) {
  const std::string prefix = "lpv[" + std::to_string(c.desc().cascade_index) + "].sh cell ";
  for (uint32_t i = 0; i < c.cell_count(); ++i)
    for (uint32_t k = 0; k < 12; ++k) scan.check(c.sh(i, k / 4, k % 4), [&] { return prefix + std::to_string(i); });
}

// Every LPV cell is a sum of non-negative intensities (cosine lobes), so per channel c0 >= 0 and
// the band-1 vector is at most sqrt(3) c0 (the bound of a non-negative function; a delta reaches it).
void check_lpv(const loader::LpvCascade& c, VerifyReport& report) {
  double peak = 0.0;
  for (uint32_t i = 0; i < c.cell_count(); ++i)
    for (uint32_t k = 0; k < 3; ++k) peak = std::max(peak, double(c.sh(i, k, 0)));
  const double eps = 1e-5 * peak + 1e-30;
  int64_t bad_cell = -1;
  double worst = 0.0;  // how far the worst cell is outside the bound, relative to the peak
  for (uint32_t i = 0; i < c.cell_count(); ++i)
    for (uint32_t k = 0; k < 3; ++k) {
      const double c0 = c.sh(i, k, 0), c1 = c.sh(i, k, 1), c2 = c.sh(i, k, 2), c3 = c.sh(i, k, 3);
      const double excess = std::max(-c0, std::sqrt(c1 * c1 + c2 * c2 + c3 * c3) - std::sqrt(3.0) * c0);
      if (excess > eps && excess > worst) {
        worst = excess;
        bad_cell = i;
      }
    }
  const std::string name = "lpv[" + std::to_string(c.desc().cascade_index) + "].nonnegative";
  json details{{"worst_cell", bad_cell}, {"excess", worst}, {"peak_c0", peak}};
  if (bad_cell >= 0)
    add(report, name, "fail", "cell " + std::to_string(bad_cell) + " is not a non-negative intensity (excess " +
                                  std::to_string(worst) + " cd)", details);
  else
    add(report, name, "pass", "every cell is a non-negative intensity (c0 >= 0, |c1| <= sqrt(3) c0)", details);
}

}  // namespace

// FORMAT.md: the metadata section holds one JSON object. Its settings and input digest are what
// --scene's staleness reads; text that is not one would pass for a bake from before digests.
void check_metadata(const loader::BakeFile& file, VerifyReport& report) {
  const std::string text = file.metadata_json();
  if (text.empty()) {
    add(report, "metadata", "pass", "no metadata section");
    return;
  }
  const json meta = json::parse(text, nullptr, false);
  if (meta.is_object())
    add(report, "metadata", "pass", "one JSON object");
  else
    add(report, "metadata", "fail",
        meta.is_discarded() ? "the metadata section is not JSON" : "the metadata section is JSON but not one object");
}

void sanity_checks(const loader::BakeFile& file, VerifyReport& report) {
  check_metadata(file, report);
  FiniteScan scan;
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i) scan_volume(file.ddgi_volumes()[i], i, scan);
  for (const loader::LpvCascade& c : file.lpv_cascades()) scan_lpv(c, scan);
  if (scan.bad)
    add(report, "finite", "fail",
        std::to_string(scan.bad) + " NaN/Inf values (or beyond 1e36, where samplers overflow), first in " + scan.first,
        {{"count", scan.bad}, {"first", scan.first}});
  else
    add(report, "finite", "pass", "no NaN or Inf values, none beyond 1e36");
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i) {
    check_states(file.ddgi_volumes()[i], i, report);
    check_negative(file.ddgi_volumes()[i], i, report);
    check_ringing(file.ddgi_volumes()[i], i, report);
  }
  verify_vxgi(file, report);
  if (scan.bad) return;  // the bound below is meaningless on NaN
  for (const loader::LpvCascade& c : file.lpv_cascades()) check_lpv(c, report);
}

}  // namespace verify_detail

uint64_t count_non_finite_light(const loader::BakeFile& file, std::string& first) {
  verify_detail::FiniteScan scan;
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i)
    verify_detail::scan_volume(file.ddgi_volumes()[i], i, scan, /*sh_only=*/true);
  for (const loader::LpvCascade& c : file.lpv_cascades()) verify_detail::scan_lpv(c, scan);
  first = scan.first;
  return scan.bad;
}

Status check_values_readable(const loader::BakeFile& file, const std::string& path) {
  const std::string why = " though the checksums hold: the file was written wrong; 'gibake verify' checks all of it";
  verify_detail::FiniteScan scan;
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i) verify_detail::scan_volume(file.ddgi_volumes()[i], i, scan);
  for (const loader::LpvCascade& c : file.lpv_cascades()) verify_detail::scan_lpv(c, scan);
  if (scan.bad)
    return Status::invalid(path, scan.first,
                           std::to_string(scan.bad) +
                               " value(s) NaN or infinite (or beyond 1e36, where a sampler's sums "
                               "overflow)" +
                               why);
  VerifyReport vxgi;
  verify_vxgi(file, vxgi);
  const std::string finite = ".finite";
  for (const VerifyCheck& c : vxgi.checks)
    if (c.status == "fail" && c.name.size() > finite.size() &&
        c.name.compare(c.name.size() - finite.size(), finite.size(), finite) == 0)
      return Status::invalid(path, c.name.substr(0, c.name.size() - finite.size()), c.message + why);
  VerifyReport meta;
  verify_detail::check_metadata(file, meta);
  if (meta.checks.back().status == "fail")
    return Status::invalid(path, "metadata", meta.checks.back().message + ": the file was written wrong");
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i) {
    VerifyReport states;
    verify_detail::check_states(file.ddgi_volumes()[i], i, states);
    if (states.checks.back().status == "fail")
      return Status::invalid(path, states.checks.back().name,
                             states.checks.back().message + " though the checksums hold: the file was written wrong");
  }
  return Status::ok();
}

using verify_detail::add;

namespace {

int code_of(const Status& s) { return static_cast<int>(s.code()); }

// A shard file (gibake bake --shard): every shard section consistent with its info, finite values.
void shard_check(const std::string& path, VerifyReport& report) {
  std::vector<DdgiShard> volumes;
  if (Status s = read_shard_volumes(path, volumes, nullptr); !s) {
    add(report, "shard", "fail", s.message());
    return;
  }
  size_t bad = 0;
  for (const DdgiShard& v : volumes)
    for (const std::vector<float>* a : {&v.sh0, &v.irradiance, &v.depth_tiles, &v.bounce_hits})
      for (float x : *a) bad += !std::isfinite(x);
  const DdgiShard& shard = volumes[0];
  const std::string what = "shard " + std::to_string(shard.range.index) + " of " + std::to_string(shard.range.count) +
                           ", probes [" + std::to_string(shard.range.begin) + ", " + std::to_string(shard.range.end) + ")";
  if (bad)
    add(report, "shard", "fail", what + ": " + std::to_string(bad) + " NaN/Inf values");
  else
    add(report, "shard", "pass", what + ": sections consistent, values finite",
        {{"index", shard.range.index}, {"count", shard.range.count}, {"probe_begin", shard.range.begin},
         {"probe_end", shard.range.end}});
}

bool failed(const VerifyReport& r, size_t from) {
  for (size_t i = from; i < r.checks.size(); ++i)
    if (r.checks[i].status == "fail") return true;
  return false;
}

// Opens a bake file for the report; on failure the check `check` fails with the error, which
// also ends the run (report.error, report.exit_code).
bool open_checked(const std::string& path, const std::string& check, loader::BakeFile& file, VerifyReport& report) {
  const Status s = open_bake_file(path, file);
  if (s) return true;
  add(report, check, "fail", s.message());
  report.error = s.message();
  report.exit_code = code_of(s);
  return false;
}

}  // namespace

VerifyReport run_verify(const VerifyOptions& options, const Context& ctx) {
  VerifyReport report;
  report.options = options;
  loader::BakeFile file;
  if (!open_checked(options.path, "integrity", file, report)) return report;
  add(report, "integrity", "pass", "header, section table, sections and checksums valid",
      {{"sections", file.sections().size()}, {"volumes", file.ddgi_volumes().size()},
       {"lpv_cascades", file.lpv_cascades().size()}});
  verify_detail::sanity_checks(file, report);
  if (!shard_info_json(file).is_null()) shard_check(options.path, report);
  const char* no_reference = "no reference: --against REF compares the bake with one";
  const char* no_scene = "needs --scene (the scene the bake was made from)";
  const char* const scene_check_names[] = {"staleness", "lit", "energy_bound"};
  if (failed(report, 0)) {  // the comparisons and the scene's checks do not run: said so, each
    const char* invalid = "not run: the file failed the checks above";
    add(report, "against", "skip", options.against.empty() ? no_reference : invalid);
    for (const char* name : scene_check_names) add(report, name, "skip", options.scene.empty() ? no_scene : invalid);
    report.exit_code = static_cast<int>(ExitCode::InvalidInput);
    return report;
  }
  const size_t differences_from = report.checks.size();
  if (!options.against.empty()) {
    loader::BakeFile ref;
    if (!open_checked(options.against, "against.integrity", ref, report)) return report;
    // A reference whose values are not usable is an invalid input, not a difference.
    if (const Status usable = check_values_readable(ref, options.against); !usable) {
      add(report, "against.integrity", "fail", usable.message());
      report.error = usable.message();
      report.exit_code = code_of(usable);
      return report;
    }
    verify_detail::compare_files(file, ref, options, report);
  } else {
    add(report, "against", "skip", no_reference);
  }
  if (!options.scene.empty()) {
    verify_detail::scene_checks(file, options.scene, ctx, report);
  } else {
    for (const char* name : scene_check_names) add(report, name, "skip", no_scene);
  }
  if (!report.error.empty()) return report;  // scene import failed: exit code already set
  report.exit_code = failed(report, differences_from) ? static_cast<int>(ExitCode::VerifyMismatch) : 0;
  return report;
}

const std::vector<std::string>& requirable_checks() {
  static const std::vector<std::string> kinds{"staleness", "lit", "energy", "against", "reconstruction"};
  return kinds;
}

namespace {

// Whether a check belongs to a kind of --require.
bool of_kind(const std::string& name, const std::string& kind) {
  if (kind == "energy") return name == "energy_bound";
  if (kind == "against") return name == "against" || name.rfind("against.", 0) == 0;
  return name == kind;
}

}  // namespace

void apply_requirements(VerifyReport& report) {
  for (const std::string& kind : report.options.require) {
    bool ran = false;
    std::string why = "it was not run";
    for (const VerifyCheck& c : report.checks) {
      if (!of_kind(c.name, kind)) continue;
      if (c.status != "skip") ran = true;
      else why = c.message;
    }
    if (ran) continue;
    add(report, "require." + kind, "fail", "--require " + kind + ": the check was skipped: " + why);
    if (report.exit_code == 0) report.exit_code = static_cast<int>(ExitCode::VerifyMismatch);
  }
}

nlohmann::json verify_report_json(const VerifyReport& r) {
  nlohmann::json checks = nlohmann::json::array(), skipped = nlohmann::json::array();
  bool only_requirements = r.exit_code == 7;  // what failed is only that required checks did not run
  for (const VerifyCheck& c : r.checks) {
    checks.push_back({{"name", c.name}, {"status", c.status}, {"message", c.message}, {"details", c.details}});
    if (c.status == "skip") skipped.push_back(c.name);
    if (c.status == "fail" && c.name.rfind("require.", 0) != 0) only_requirements = false;
  }
  const char* result = r.exit_code == 0 ? "ok"
                       : only_requirements ? "incomplete"
                       : r.exit_code == 7 ? "differs"
                       : r.exit_code == 3 ? "invalid"
                       : r.exit_code == 2 ? "io_error"
                                          : "error";
  nlohmann::json out{{"file", r.options.path},
                     {"against", r.options.against.empty() ? nlohmann::json() : nlohmann::json(r.options.against)},
                     {"scene", r.options.scene.empty() ? nlohmann::json() : nlohmann::json(r.options.scene)},
                     {"compare", r.options.compare},
                     {"tolerance", r.options.tolerance},
                     {"require", r.options.require},
                     {"result", result},
                     {"exit_code", r.exit_code},
                     {"checks", std::move(checks)},
                     {"skipped", std::move(skipped)}};
  if (r.options.compare == "statistical")
    out["statistical"] = {{"sigmas", r.options.statistical.sigmas},
                          {"max_fraction", r.options.statistical.max_fraction},
                          {"depth", r.options.statistical.depth},
                          {"bias_floor", r.options.statistical.bias_floor}};
  if (!r.error.empty()) out["error"] = r.error;
  return out;
}

void print_verify_text(const VerifyReport& r, std::ostream& out) {
  std::string skipped;
  for (const VerifyCheck& c : r.checks) {
    out << c.status << "  " << c.name << ": " << c.message << "\n";
    if (c.status == "skip") skipped += (skipped.empty() ? "" : ", ") + c.name;
  }
  out << r.options.path << ": " << verify_report_json(r)["result"].get<std::string>();
  if (!skipped.empty()) out << " (not checked: " << skipped << ")";
  out << "\n";
}

}  // namespace gibake
