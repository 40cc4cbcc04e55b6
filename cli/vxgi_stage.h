// The bake command's --vxgi part: options, settings and the summary line (the stage itself is the
// pipeline's, bake/pipeline/stages.cpp).
#pragma once
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "bake/ddgi/ddgi.h"
#include "bake/scene/prepare.h"
#include "bake/vxgi/vxgi.h"
#include "cli/progress.h"
#include "io/context.h"
#include "io/results/vxgi_result.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake::cli {

struct VxgiArgs {
  bool enabled = false;  // --vxgi
  int res = 64;
  uint64_t max_bytes = uint64_t(16) << 30;  // --max-memory (set with BakeArgs::max_memory)
  int bounces = 4;
  uint32_t rays = 64;
  std::string sdf = "on";
  std::string format = "auto";  // --vxgi-format auto|f16|f32
  uint32_t calibrate = 256;     // --vxgi-calibrate N: points of the diffuse_scale fit (0: off)
  int clipmaps = 1;             // --vxgi-clipmaps K
  std::string center;           // --vxgi-center x,y,z (empty: the scene's centre)
  bool precompute_cones = false;  // --vxgi-precompute-cones
  std::string sides = "mixed";    // --vxgi-sides mixed|split
  int align_walls = 0;            // --vxgi-align-walls L (split sides only)
};

void add_vxgi_options(CLI::App* sub, VxgiArgs& args);
Status to_vxgi_settings(const VxgiArgs& a, uint64_t seed, float blend_cutoff, VxgiSettings& out);
void print_vxgi_summary(const VxgiResult& r, ProgressMode mode);

}  // namespace gibake::cli
