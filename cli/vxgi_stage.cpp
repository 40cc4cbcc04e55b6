#include "cli/vxgi_stage.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "bake/scene/lights.h"
#include "bake/scene/sky.h"
#include "cli/bake_args.h"
#include "cli/options.h"

namespace gibake::cli {

void add_vxgi_options(CLI::App* sub, VxgiArgs& a) {
  sub->add_flag("--vxgi", a.enabled, "bake voxel GI volumes (anisotropic voxel radiance and mips) into the bake file");
  sub->add_option("--vxgi-res", a.res, "voxel GI voxels on the scene's longest axis (default 64)");
  sub->add_option("--vxgi-bounces", a.bounces, "voxel GI path vertices after the voxel's surface (default 4)");
  sub->add_option("--vxgi-rays", a.rays, "voxel GI rays per voxel face (default 64)");
  sub->add_option("--vxgi-sdf", a.sdf, "on|off: store the empty-space distance for SDF-accelerated cones (default on)");
  sub->add_option("--vxgi-calibrate", a.calibrate,
                  "surface points where the diffuse cone trace is fitted to the path tracer (default 256; 0: off)");
  sub->add_option("--vxgi-format", a.format, "auto|f16|f32: voxel radiance storage (auto: RGBA16F when it fits)");
  sub->add_option("--vxgi-clipmaps", a.clipmaps,
                  "voxel GI clipmaps (default 1): K volumes of the same voxel counts, the coarsest over the scene, each "
                  "finer one half the extent around --vxgi-center");
  sub->add_flag("--vxgi-precompute-cones", a.precompute_cones,
                "store seed 000's 16 cone-direction slices beside the six faces (read by the seed's diffuse cone set)");
  sub->add_option("--vxgi-sides", a.sides,
                  "mixed|split: both sides of a surface in the voxel holding it (default), or each side in the "
                  "voxel on that side (no thin-wall leak at level 0; docs/BENCHMARKS.md)");
  sub->add_option("--vxgi-align-walls", a.align_walls,
                  "with --vxgi-sides split and one volume: move the grid by up to 2^L - 1 voxels per axis so "
                  "double-sided walls' two layers stay apart up to mip level L (0..6; default 0: off)");
  sub->add_option("--vxgi-center", a.center, "x,y,z in metres: centre of the finer clipmaps (default: the scene's centre)");
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
    GIBAKE_TRY(parse_vec3("--vxgi-center", a.center, s.center));
    s.has_center = true;
  }
  s.align_levels = a.align_walls;
  if (a.sides == "split") s.split_sides = true;
  else if (a.sides == "mixed") s.split_sides = false;
  else return bad_arg("--vxgi-sides", "expected 'split' or 'mixed'");
  if (a.sdf == "on") s.sdf = true;
  else if (a.sdf == "off") s.sdf = false;
  else return bad_arg("--vxgi-sdf", "expected 'on' or 'off'");
  FloatPrecision p;
  if (!parse_precision(a.format, p)) return bad_arg("--vxgi-format", "expected auto, f16 or f32");
  return validate_vxgi_settings(s);
}

Status run_vxgi_stage(const VxgiArgs& a, const DdgiSettings& ddgi, uint64_t seed, float blend_cutoff,
                      const Scene& scene, const PreparedScene& prepared, const Context& ctx, VxgiResult& out) {
  VxgiSettings s;
  GIBAKE_TRY(to_vxgi_settings(a, seed, blend_cutoff, s));
  Sky sky;
  sky.constant = {ddgi.sky[0], ddgi.sky[1], ddgi.sky[2]};
  if (!ddgi.sky_hdr.empty()) {
    GIBAKE_TRY(load_sky_exr(ddgi.sky_hdr, sky));
    sky.scale = ddgi.sky_hdr_scale;
  }
  return bake_vxgi(scene, prepared, shade_lights(scene, ddgi.suns), sky, s, ctx, out);
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
