// Why one pixel of a lit preview reads what it reads (`gibake preview --explain X,Y`).
//
// At the surface the pixel's centre sees, it lists the probes the loader's sampler weighs there
// (their weight's factors and share), each probe's baked irradiance for the surface's normal, and
// three path-traced irradiances for that normal, each the mean of `paths` cosine-distributed paths
// of the reference's tracer (converged: path_gather.h):
//   here         at the surface point: the truth the pixel should read;
//   at a probe   at each listed probe's position: what the probe would hold if its rays converged;
//   along n      at points 0.1, 0.25 and 0.5 of the finest listed volume's spacing above the surface.
// Blending the probes' path-traced values with the sampler's shares gives what exact probes would
// read here, which splits the pixel's error in two:
//   the probes' error        baked / exact probes (too few rays, the probe filter),
//   the interpolation error  exact probes / here (what a probe grid of this spacing cannot hold:
//                            light that changes between the probes and the surface).
// Irradiance is indirect light only (the sampler's E: the punctual lights' direct light is traced
// per pixel), luminance in lux. Deterministic for the inputs and seed, whatever the thread count.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "bake/preview/preview.h"

namespace gibake {

struct ExplainSettings {
  int x = 0, y = 0;       // the pixel, from the image's top-left corner
  uint32_t paths = 4096;  // paths per path-traced irradiance
};

// A path-traced irradiance (luminance, lux) and its relative standard error.
struct TracedIrradiance {
  double lux = 0.0;
  double relative_error = 0.0;
};

struct ExplainedProbe {
  uint32_t volume = 0;  // index into the file's DDGI volumes
  loader::ProbeWeight weight;
  float share = 0.f;         // of the sampler's answer: the volume's share x weight / the volume's weights
  kernels::float3 position;  // relocated
  uint32_t state = 0;        // GIBAKE_PROBE_*
  // Past the surface's tangent plane at the point: the probe sees the surface's other side, and
  // reaches the point only once the sampler's normal bias has lifted it off a curved or thin
  // surface. Its light there is a leak.
  bool behind = false;
  double baked_lux = 0.0;    // the probe's own irradiance for the surface's normal
  TracedIrradiance traced;   // path-traced at the probe for the surface's normal
};

struct ExplainedPixel {
  bool hit = false;        // false: the pixel sees the sky, nothing to explain
  bool back_face = false;  // the back of a single-sided surface: black, nothing to explain
  int width = 0, height = 0;
  std::string camera;
  uint32_t triangle = 0;
  std::string material;
  kernels::float3 point, normal, albedo;
  kernels::float3 direct;  // the punctual lights' reflected radiance and emission, cd/m^2
  kernels::float3 baked;   // the sampler's irradiance, lux (RGB)
  double baked_lux = 0.0;
  TracedIrradiance here;
  float spacing = 0.f;                                           // the finest spacing among the listed volumes, metres
  std::vector<std::pair<float, TracedIrradiance>> along_normal;  // metres above the point
  std::vector<ExplainedProbe> probes;
  // Each listed volume's sight of the point (docs/FORMAT.md "Several volumes"): below
  // GIBAKE_DDGI_FULL_SIGHT its blend weight is scaled down and the next volume answers the rest.
  std::vector<std::pair<uint32_t, float>> sights;
  double exact_probes_lux = 0.0;  // sum of share x traced over the probes
  uint32_t paths = 0;
};

// Explains pixel (x, y) of the view `settings` describes (its camera, size, sampler options, volume
// and lights, as render_preview takes them). The bake must hold DDGI volumes.
Status explain_pixel(const PreparedScene& prepared, const loader::BakeFile& bake, const PreviewSettings& settings,
                     const ExplainSettings& explain, const Context& ctx, ExplainedPixel& out);

// The probes behind the surface (ExplainedProbe::behind) together: how many, their share of the
// sampler's weight and of its baked irradiance (share x baked lux over all the listed probes').
struct BehindSurface {
  uint32_t probes = 0;
  double weight = 0.0, light = 0.0;
};
BehindSurface probes_behind(const ExplainedPixel& e);

// The explanation as lines of text for a terminal.
std::string explain_text(const ExplainedPixel& e);

}  // namespace gibake
