// `gibake verify`: integrity, sanity, staleness and comparison of bake files.
// Report schema: docs/verify-report.schema.json. Exit codes: 0 all checks hold, 7 a difference
// (against the reference, a stale input hash, an energy bound exceeded), 3 the file is invalid
// (loader validation, NaN/Inf, negative irradiance), 2 I/O failure.
#pragma once
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct VerifyOptions {
  std::string path;
  std::string against;       // reference bake file; empty: no comparison
  double tolerance = 1e-4;   // per value: |a - ref| <= tolerance * max(1, |ref|)
  std::string scene;         // scene for staleness and energy checks; empty: skipped
};

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
nlohmann::json verify_report_json(const VerifyReport& report);
void print_verify_text(const VerifyReport& report, std::ostream& out);

namespace verify_detail {
// Fixed direction set for SH evaluation (spherical Fibonacci, 64 directions).
const std::vector<loader::Vec3>& directions();
// E(n) without clamping (may be negative: SH ringing).
loader::Rgb sh_irradiance_raw(const loader::DdgiVolume& v, uint32_t probe, const loader::Vec3& n);
void sanity_checks(const loader::BakeFile& file, VerifyReport& report);
void compare_files(const loader::BakeFile& a, const loader::BakeFile& b, double tolerance, VerifyReport& report);
void scene_checks(const loader::BakeFile& file, const std::string& scene, const Context& ctx, VerifyReport& report);
void add(VerifyReport& report, std::string name, std::string status, std::string message,
         nlohmann::json details = nlohmann::json::object());
// The largest albedo a triangle can have: its material's base colour times the brightest texel of
// its base-colour texture (and the brightest vertex colour); 1 where a triangle has no material.
double max_used_albedo(const Scene& scene);
// "lit": fails a bake whose sampled probes all read zero while the scene or settings bring light.
void black_bake_check(const loader::BakeFile& file, const Scene& scene, const nlohmann::json& settings, double sky,
                      double sun_lux, VerifyReport& report);
}  // namespace verify_detail

}  // namespace gibake
