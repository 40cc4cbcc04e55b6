#include "cli/vxgi_stage.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli/bake_args.h"
#include "cli/help.h"
#include "cli/options.h"

namespace gibake::cli {

void add_vxgi_options(CLI::App* sub, VxgiArgs& a) {
  OptionGroup g(*sub, "Voxel GI (--vxgi)");
  g.option("--vxgi-res", a.res, "N", "voxels on the scene's longest axis")->capture_default_str();
  g.option("--vxgi-rays", a.rays, "N", "path-traced rays per voxel face")->capture_default_str();
  g.option("--vxgi-bounces", a.bounces, "N", "path vertices after the voxel's own surface")->capture_default_str();
  g.option("--vxgi-calibrate", a.calibrate, "N", "points fitting the diffuse cones to paths; 0: off")
      ->capture_default_str();
  g.option("--vxgi-sdf", a.sdf, "on|off", "store the empty-space distance for faster cones")->capture_default_str();
  g.option("--vxgi-format", a.format, "auto|f16|f32", "radiance storage; auto: f16 where every value fits")
      ->capture_default_str();
  g.option("--vxgi-clipmaps", a.clipmaps, "K", "nested volumes, each half the extent of the next")
      ->capture_default_str();
  g.option("--vxgi-center", a.center, "X,Y,Z", "centre of the finer clipmaps, metres (unset: the scene's)");
  g.option("--vxgi-sides", a.sides, "mixed|split", "both sides in one voxel, or each in its side's voxel")
      ->capture_default_str();
  g.option("--vxgi-align-walls", a.align_walls, "L", "with split sides: keep wall layers apart to mip L (0..6)")
      ->capture_default_str();
  g.flag("--vxgi-precompute-cones", a.precompute_cones,
         "also store radiance along the 16 fixed cone directions (3.7x size)");
}

Status to_vxgi_settings(const VxgiArgs& a, uint64_t seed, float blend_cutoff, VxgiSettings& s) {
  s.resolution = a.res;
  s.max_bytes = a.max_bytes;
  s.bounces = a.bounces;
  s.rays = a.rays;
  s.seed = seed;
  s.blend_cutoff = blend_cutoff;
  s.calibration_points = a.calibrate;
  s.clipmaps = a.clipmaps;
  s.precompute_cones = a.precompute_cones;
  if (!a.center.empty()) {
    GIBAKE_TRY(parse_place("--vxgi-center", a.center, s.center));
    s.has_center = true;
  }
  s.align_levels = a.align_walls;
  if (a.sides == "split") s.split_sides = true;
  else if (a.sides == "mixed") s.split_sides = false;
  else return bad_arg("--vxgi-sides", "expected 'split' or 'mixed', got '" + a.sides + "'");
  // Options that act only with another are refused without it, not recorded as if they had acted.
  if (s.has_center && s.clipmaps < 2)
    return bad_arg("--vxgi-center", "centres the finer clipmaps: only with --vxgi-clipmaps 2 or more");
  if (s.align_levels > 0 && (!s.split_sides || s.clipmaps > 1))
    return bad_arg("--vxgi-align-walls", "only with --vxgi-sides split and one clipmap (--vxgi-clipmaps 1)");
  GIBAKE_TRY(parse_on_off("--vxgi-sdf", a.sdf, s.sdf));
  FloatPrecision p;
  if (!parse_precision(a.format, p)) return bad_arg("--vxgi-format", "expected auto, f16 or f32, got '" + a.format + "'");
  return validate_vxgi_settings(s);
}

void print_vxgi_summary(const VxgiResult& r, ProgressMode mode) {
  if (r.clipmaps.empty()) return;
  const VxgiClipmap& c = r.clipmaps.front();  // the finest
  const VxgiStats& st = r.stats;
  if (mode == ProgressMode::Json) {
    nlohmann::json j{{"event", "vxgi"},
                     {"dims", c.dims},
                     {"voxel_size", c.voxel_size},
                     {"levels", c.levels.size()},
                     {"clipmaps", r.clipmaps.size()},
                     {"surface_voxels", st.surface_voxels},
                     {"interior_voxels", st.interior_voxels},
                     {"faces_traced", st.faces_traced},
                     {"rays", st.rays + st.shadow_rays + st.bounce_rays},
                     {"estimated_bytes", st.estimated_bytes},
                     {"diffuse_scale", c.diffuse_scale},
                     {"calibration_error", c.calibration_error},
                     {"uncalibrated_error", st.uncalibrated_error},
                     {"seconds", {{"voxelize", st.seconds_voxelize}, {"radiance", st.seconds_radiance}, {"mips", st.seconds_mips}}}};
    std::fprintf(stderr, "%s\n", j.dump().c_str());
    return;
  }
  if (r.clipmaps.size() > 1)
    std::fprintf(stderr, "  vxgi: %zu clipmaps, voxels of %.4g m to %.4g m (the finest below)\n", r.clipmaps.size(),
                 double(c.voxel_size), double(r.clipmaps.back().voxel_size));
  std::fprintf(stderr,
               "  vxgi: %dx%dx%d voxels of %.4g m, %zu mip levels; %llu surface voxels (%llu faces traced), %llu inside "
               "solids; %llu rays; seconds: voxelize %.2f, radiance %.2f, mips %.2f\n",
               c.dims[0], c.dims[1], c.dims[2], double(c.voxel_size), c.levels.size(),
               static_cast<unsigned long long>(st.surface_voxels), static_cast<unsigned long long>(st.faces_traced),
               static_cast<unsigned long long>(st.interior_voxels),
               static_cast<unsigned long long>(st.rays + st.shadow_rays + st.bounce_rays), st.seconds_voxelize,
               st.seconds_radiance, st.seconds_mips);
  if (c.calibration_points)
    std::fprintf(stderr, "  vxgi calibration: diffuse scale %.3f from %u points (relative RMS against the path tracer %.3f "
                 "before, %.3f after)\n", double(c.diffuse_scale), c.calibration_points, double(st.uncalibrated_error),
                 double(c.calibration_error));
}

}  // namespace gibake::cli
