// `gibake verify`: integrity, sanity, staleness and comparison of bake files.
// Report schema: docs/verify-report.schema.json. Exit codes: 0 all checks hold, 7 a difference
// (against the reference, a stale input hash, an energy bound exceeded), 3 the file is invalid
// (loader validation, NaN/Inf, negative irradiance, an undefined probe state), 2 I/O failure.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

// --compare statistical: two Monte Carlo bakes of one scene and settings (another backend, another
// seed) are judged by shares of probes and texels beyond bounds set by the probes' own noise.
struct StatisticalOptions {
  double sigmas = 5.0;         // a difference beyond this many of the pair's noise counts as beyond
  double max_fraction = 0.01;  // share of probe states, probes or texels allowed beyond, per check
  // A depth texel is beyond when its mean distance differs by more than this fraction of
  // max(the reference's, the probe spacing).
  double depth = 0.5;
  // The volume's mean irradiance may differ by sigmas x its noise, and at least this fraction.
  double bias_floor = 0.005;
};

struct VerifyOptions {
  std::string path;
  std::string against;       // reference bake file; empty: no comparison
  std::string compare = "values";  // "values" (per value, `tolerance`) or "statistical" (`statistical`)
  double tolerance = 1e-4;   // per value: |a - ref| <= tolerance * max(1, |ref|)
  StatisticalOptions statistical;
  std::string scene;         // scene for staleness and energy checks; empty: skipped (and listed so)
  // Kinds of check that must run (requirable_checks()): one that is skipped fails the verify (exit 7).
  std::vector<std::string> require;
};

// The kinds of check --require names: staleness, lit, energy, against, reconstruction.
const std::vector<std::string>& requirable_checks();

struct VerifyCheck {
  std::string name;     // e.g. "integrity", "finite", "against.sh_irradiance"
  std::string status;   // "pass", "fail", "warn", "skip"
  std::string message;
  nlohmann::json details = nlohmann::json::object();
};

struct VerifyReport {
  VerifyOptions options;
  std::vector<VerifyCheck> checks;
  int exit_code = 0;
  std::string error;  // set when a file could not be read or is invalid
};

VerifyReport run_verify(const VerifyOptions& options, const Context& ctx);

// verify's NaN/Inf scans (DDGI, LPV and voxel GI values) and its probe-state check, for the
// commands that read a bake's values (export, sample, preview, verify's --against): a file whose
// checksums hold but whose values do not (a writer's bug, an edit that recomputed the checksums)
// is invalid (exit 3), named by its first such value's place, instead of turning into NaN output
// or a probe of a state no sampler defines. The loader leaves values to the engine; one pass
// costs a command far less than its own reads.
Status check_values_readable(const loader::BakeFile& file, const std::string& path);
// How many values of the light itself (DDGI and LPV SH) are NaN or infinite, and the first one's
// place: the writer's check, cheap enough for every bake.
uint64_t count_non_finite_light(const loader::BakeFile& file, std::string& first);

// --require: each required kind of which no check ran (absent or skipped) adds a failing
// "require.<kind>" check naming why, exit 7 unless another code is set. Called after every check.
void apply_requirements(VerifyReport& report);
nlohmann::json verify_report_json(const VerifyReport& report);
void print_verify_text(const VerifyReport& report, std::ostream& out);

namespace verify_detail {
// Fixed direction set for SH evaluation (spherical Fibonacci, 64 directions).
const std::vector<loader::Vec3>& directions();
// E(n) without clamping (may be negative: SH ringing).
loader::Rgb sh_irradiance_raw(const loader::DdgiVolume& v, uint32_t probe, const loader::Vec3& n);
void sanity_checks(const loader::BakeFile& file, VerifyReport& report);
void compare_files(const loader::BakeFile& a, const loader::BakeFile& b, const VerifyOptions& options,
                   VerifyReport& report);
// One DDGI volume of the same shape as the reference's, by --compare statistical (bake_compare_stat.cpp).
void compare_volume_statistical(const loader::DdgiVolume& a, const loader::DdgiVolume& b, const std::string& prefix,
                                const StatisticalOptions& options, VerifyReport& report);
void scene_checks(const loader::BakeFile& file, const std::string& scene, const Context& ctx, VerifyReport& report);
void add(VerifyReport& report, std::string name, std::string status, std::string message,
         nlohmann::json details = nlohmann::json::object());
// Accumulates |a - ref| over values, judged as |a - ref| <= tolerance * max(1, |ref|).
struct DiffStats {
  double max_abs = 0.0, sum_sq = 0.0, worst_score = 0.0;
  uint64_t count = 0;
  int64_t worst_item = -1;
  void add(double a, double ref, int64_t item) {
    const double d = std::fabs(a - ref);
    const double score = std::isnan(d) ? std::numeric_limits<double>::infinity() : d / std::max(1.0, std::fabs(ref));
    max_abs = std::max(max_abs, d);
    sum_sq += d * d;
    ++count;
    if (score > worst_score) {
      worst_score = score;
      worst_item = item;
    }
  }
  double rms() const { return count ? std::sqrt(sum_sq / double(count)) : 0.0; }
};
// Adds check `name`: pass, or fail naming the worst item ("probe", "texel") beyond the tolerance.
void judge(VerifyReport& report, const std::string& name, const DiffStats& s, double tolerance,
           const std::string& item_label, const std::string& units);
// The largest albedo a triangle can have: its material's base colour times the brightest texel of
// its base-colour texture (and the brightest vertex colour); 1 where a triangle has no material.
double max_used_albedo(const Scene& scene);
// "lit": fails a bake whose sampled probes all read zero while the scene or settings bring light.
void black_bake_check(const loader::BakeFile& file, const Scene& scene, const nlohmann::json& settings, double sky,
                      double sun_lux, VerifyReport& report);
}  // namespace verify_detail

}  // namespace gibake
