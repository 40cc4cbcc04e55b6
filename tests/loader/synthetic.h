// Synthetic DDGI results for loader/writer tests, the atomic-write helper and fuzz seeds.
#pragma once
#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "io/bakefile/bake_file.h"
#include "io/results/ddgi_result.h"
#include "io/results/lpv_result.h"

namespace gibake::test {

// The bytes of a file holding `r` alone, its atlases stored as `atlas` says; empty when the writer
// refuses it (the loader then refuses the empty buffer, so a test's open fails).
inline std::vector<uint8_t> one_volume_file(const DdgiResult& r, FloatPrecision atlas) {
  BakeOutputs outputs;
  outputs.ddgi = &r;
  outputs.metadata_json = "{}";
  BakeFileOptions options;
  options.atlas = atlas;
  std::vector<uint8_t> bytes;
  if (!build_bake_file(outputs, options, bytes).is_ok()) bytes.clear();
  return bytes;
}

inline DdgiResult make_ddgi(int nx, int ny, int nz, int sh_order, uint32_t seed, bool atlases = true) {
  DdgiResult r;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  r.desc.counts = {nx, ny, nz};
  r.desc.grid_min = {-1.f, 0.f, -2.f};
  r.desc.spacing = {nx > 1 ? 1.5f : 0.f, ny > 1 ? 1.f : 0.f, nz > 1 ? 2.f : 0.f};
  for (int a = 0; a < 3; ++a)
    r.desc.grid_max[a] = r.desc.grid_min[a] + r.desc.spacing[a] * float(r.desc.counts[a] - 1);
  r.desc.sh_order = sh_order;
  r.desc.max_distance = 10.f;
  const size_t probes = size_t(r.desc.probe_count());
  const int coefficients = r.desc.sh_coefficients();
  for (size_t p = 0; p < probes; ++p)
    for (int c = 0; c < coefficients; ++c)
      for (int k = 0; k < 3; ++k) r.sh.push_back(c == 0 ? 1.f + 10.f * u(rng) : (u(rng) - 0.5f) * 0.5f);
  for (size_t i = 0; i < probes * 3; ++i) r.offsets.push_back((u(rng) - 0.5f) * 0.1f);
  for (size_t p = 0; p < probes; ++p) {
    r.states.push_back(p % 5 == 4 ? ProbeState::Inactive : ProbeState::Active);
    r.stats.push_back({uint32_t(256 + p), u(rng) * 0.1f, u(rng) * 3.f, u(rng) * 0.2f});
  }
  if (atlases) {
    r.irradiance_width = nx * ny * (kIrradianceTexels + 2);
    r.irradiance_height = nz * (kIrradianceTexels + 2);
    for (int i = 0; i < r.irradiance_width * r.irradiance_height; ++i) {
      for (int k = 0; k < 3; ++k) r.irradiance_atlas.push_back(100.f * u(rng));
      r.irradiance_atlas.push_back(1.f);
    }
    r.depth_width = nx * ny * (kDepthTexels + 2);
    r.depth_height = nz * (kDepthTexels + 2);
    for (int i = 0; i < r.depth_width * r.depth_height; ++i) {
      const float mean = 0.5f + 3.f * u(rng);
      r.depth_atlas.push_back(mean);
      r.depth_atlas.push_back(mean * mean + 0.01f * u(rng));
    }
  }
  r.settings_json = R"({"rays_per_probe":256,"sh_order":)" + std::to_string(sh_order) + "}";
  return r;
}

// LPV cascades centred on the origin, each twice the cell size of the previous; every cell a
// non-negative intensity (c0 > 0, |c1| < sqrt(3) c0).
inline LpvResult make_lpv(int nx, int ny, int nz, int cascades, uint32_t seed) {
  LpvResult r;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int k = 0; k < cascades; ++k) {
    LpvCascade c;
    c.dims = {nx, ny, nz};
    c.cell_size = 0.25f * float(1 << k);
    for (int a = 0; a < 3; ++a) c.grid_min[a] = -0.5f * float(c.dims[a]) * c.cell_size;
    c.iterations = uint32_t(std::max({nx, ny, nz}));
    c.occlusion = k == 0;
    for (size_t i = 0; i < c.cell_count(); ++i)
      for (int ch = 0; ch < 3; ++ch) {
        const float c0 = 0.5f + 5.f * u(rng);
        c.sh.push_back(c0);
        for (int m = 0; m < 3; ++m) c.sh.push_back((u(rng) - 0.5f) * c0);
      }
    r.cascades.push_back(std::move(c));
  }
  r.settings_json = R"({"resolution":)" + std::to_string(std::max({nx, ny, nz})) + "}";
  return r;
}

}  // namespace gibake::test
