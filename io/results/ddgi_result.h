// What a DDGI bake produces: plain data handed from bake/ddgi/ddgi to the writers (io/bake_file.h).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace gibake {

// Interior sizes of the octahedral tiles; each tile has a 1-texel border (RTXGI layout).
constexpr int kIrradianceTexels = 8;
constexpr int kDepthTexels = 16;

// Active: sampled. Inactive: inside geometry or in enclosed space no light reaches (SH zero, never
// sampled). SkyOnly: no ray met geometry; its SH holds the sky and it is sampled like an active one.
enum class ProbeState : uint8_t { Active = 0, Inactive = 1, SkyOnly = 2 };

struct DdgiProbeStats {
  uint32_t rays = 0;             // rays traced for this probe over all passes
  float relative_error = 0.f;    // estimated relative standard error of its irradiance
  float nearest_front = 0.f;     // nearest front-face hit distance (m), for relocation
  float backface_fraction = 0.f; // fraction of rays that hit back faces
};

struct DdgiVolumeDesc {
  std::array<float, 3> grid_min{};  // world position of probe (0,0,0) before relocation, metres
  std::array<float, 3> grid_max{};  // world position of probe (n-1) before relocation
  std::array<int32_t, 3> counts{};  // probes per axis; index = x + X*(y + Y*z)
  std::array<float, 3> spacing{};   // (grid_max-grid_min)/(counts-1), per axis (0 for a 1-probe axis)
  int32_t sh_order = 2;             // 1 (4 coefficients) or 2 (9 coefficients)
  float max_distance = 0.f;         // depth recorded for misses, metres
  int32_t probe_count() const { return counts[0] * counts[1] * counts[2]; }
  int32_t sh_coefficients() const { return (sh_order + 1) * (sh_order + 1); }
};

// Atlas layout (shared by irradiance and depth, kernels::AtlasLayout): with k =
// atlas_planes_per_row, probe (x,y,z) is the tile at column x + X*(y mod k), row z + Z*(y div k);
// a tile is (interior+2)^2 texels. Width = X*k*(interior+2), height = Z*ceil(Y/k)*(interior+2).
struct DdgiResult {
  DdgiVolumeDesc desc;
  // probe_count * sh_coefficients * 3 floats: incident radiance SH (cd/m^2), DESIGN.md order.
  std::vector<float> sh;
  // probe_count * 3: world-space relocation offsets (metres), added to the rest position.
  std::vector<float> offsets;
  std::vector<ProbeState> states;
  std::vector<DdgiProbeStats> stats;
  int atlas_planes_per_row = 0;  // k; 0 means Y (every plane in one band of rows)
  // RGBA float32, irradiance in lux (A = 1); width*height*4.
  int irradiance_width = 0, irradiance_height = 0;
  std::vector<float> irradiance_atlas;
  // RG float32: mean and mean^2 of hit distance (m, m^2); width*height*2; tiles of depth_tile
  // interior texels a side (kDepthTexels as baked; fewer once coarsened for the file, --depth-tile).
  int depth_width = 0, depth_height = 0, depth_tile = kDepthTexels;
  std::vector<float> depth_atlas;
  // Bake settings and timings as a JSON object (written into the metadata section).
  std::string settings_json;
  // Store only the probes a sampler reads (every probe not Inactive) with a slot map: a sparse
  // volume (format 1.5). Set where most probes were left out (a near-surface volume), where the
  // grid's own layout would store mostly nothing.
  bool sparse = false;
};

}  // namespace gibake
