// Calibration of the diffuse cone set against the path tracer (calibrated, not
// hand-tuned). Cone tracing through averaged mips loses light in closed spaces (a wide cone's
// footprint straddles walls at different depths, its averaged opacity lets part of it through to
// the black outside) and can gain it elsewhere; instead of a hand-picked factor (Wicked Engine's
// 0.5, others' /4, /8) the bake measures it: at surface points spread over the scene it compares
// the diffuse cone trace of the volume just built with the path-traced irradiance of the same
// point and normal (points in open space, below), fits one least-squares factor, and stores it (diffuse_scale) with the relative
// RMS that remains (calibration_error), so an engine knows both.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "bake/run/arena.h"
#include "bake/scene/emitters.h"
#include "bake/trace/path_gather.h"
#include "bake/vxgi/vxgi.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"

namespace gibake {
using kernels::float3;

namespace {

constexpr uint64_t kCalibrationStream = 0x7678676943616c62ull;  // "vxgiCalb"

struct CalibrationPoint {
  float3 p, n;
};

// Points in open space at least two voxels from any opaque voxel (free distance > 0), evenly
// strided over the grid, outside solids; the normal cycles through 14 directions (the 6 axes and
// the 8 diagonals). Open space, not surfaces: a point just above a sunlit floor is where cone
// tracing is least reliable (the side cones' footprints reach the receiving surface's own voxels
// through the coarse mips), and a fit there would be dominated by that error, not the scale.
std::vector<CalibrationPoint> pick_points(const VoxelGrid& g, const std::vector<uint8_t>& solid,
                                          const std::vector<float>& free, uint32_t wanted) {
  std::vector<size_t> open;
  for (size_t c = 0; c < free.size(); ++c)
    if (free[c] > 0.f && free[c] < 1e5f * g.voxel_size && !solid[c]) open.push_back(c);
  std::vector<CalibrationPoint> out;
  if (open.empty()) return out;
  const float k = 0.57735027f;
  const float3 normals[14] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {k, k, k},
                              {k, k, -k}, {k, -k, k}, {k, -k, -k}, {-k, k, k}, {-k, k, -k}, {-k, -k, k}, {-k, -k, -k}};
  const size_t stride = std::max<size_t>(1, open.size() / wanted);
  for (size_t i = 0; i < open.size() && out.size() < wanted; i += stride) {
    const size_t c = open[i];
    const int32_t x = int32_t(c % size_t(g.dims[0])), y = int32_t((c / size_t(g.dims[0])) % size_t(g.dims[1])),
                  z = int32_t(c / (size_t(g.dims[0]) * size_t(g.dims[1])));
    const std::array<float, 3> p = g.voxel_center(x, y, z);
    out.push_back({{p[0], p[1], p[2]}, normals[out.size() % 14]});
  }
  return out;
}

}  // namespace

Status vxgi_calibrate(const VoxelGrid& g, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                      const Sky& sky, const VxgiSettings& s, const Context& ctx, VxgiResult& result) {
  if (s.calibration_points == 0 || result.clipmaps.empty()) return Status::ok();
  const VxgiClipmap& clip = result.clipmaps.back();  // the coarsest: over the whole scene, as `g`
  const std::vector<float> free = clip.sdf.empty() ? vxgi_free_distance(clip.levels.front(), clip.dims, clip.voxel_size)
                                                   : clip.sdf;
  const std::vector<CalibrationPoint> points = pick_points(g, vxgi_solid_interior(g), free, s.calibration_points);
  if (points.empty()) return Status::ok();
  // The cone tracer reads the volume through the loader, exactly as an engine would.
  BakeOutputs outputs;
  outputs.vxgi = &result;
  BakeFileOptions options;
  options.vxgi = FloatPrecision::Full;
  std::vector<uint8_t> bytes;
  GIBAKE_TRY(build_bake_file(outputs, options, bytes));
  loader::BakeFile file;
  if (loader::Error e = file.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{false}))
    return Status::error(ExitCode::RuntimeFailure, "", "vxgi calibration", e.message);
  const std::vector<loader::VxgiVolume>& volume = file.vxgi_volumes();  // every clipmap
  EmitterTable emitters(prepared.scene());
  const PathSetup ps = make_path_setup(prepared, lights, sky, emitters, s.seed, s.bounces);
  std::vector<float3> traced(points.size()), coned(points.size());
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  loader::ConeOptions raw;
  raw.calibrated = false;
  arena->execute([&] {
    tbb::parallel_for(size_t(0), points.size(), [&](size_t i) {
      TraceCounters tc;
      float3 sum{0.f, 0.f, 0.f};
      for (uint32_t r = 0; r < s.calibration_rays; ++r) {
        const uint64_t key = kernels::rng_hash(s.seed, i, kCalibrationStream, r);
        const float3 dir = kernels::sample_cosine_hemisphere(points[i].n, kernels::rng_uniform(key, 0), kernels::rng_uniform(key, 1));
        sum += trace_radiance(ps, points[i].p, dir, key, tc);
      }
      traced[i] = sum * (kernels::kPi / float(s.calibration_rays));
      const loader::Rgb e = loader::cone_trace_diffuse(volume, {points[i].p.x, points[i].p.y, points[i].p.z},
                                                       {points[i].n.x, points[i].n.y, points[i].n.z}, raw);
      coned[i] = {e[0], e[1], e[2]};
    });
  });
  double tc = 0.0, cc = 0.0, tt = 0.0;  // in point order: the same sums for any thread count
  for (size_t i = 0; i < points.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double t = (&traced[i].x)[c], k = (&coned[i].x)[c];
      tc += t * k;
      cc += k * k;
      tt += t * t;
    }
  if (!(cc > 0.0) || !(tt > 0.0)) return Status::ok();  // nothing lit: nothing to fit
  // Least squares, bounded so that a scene the cones cannot see at all does not get a wild factor.
  const double scale = std::min(4.0, std::max(0.25, tc / cc));
  auto rel_rms = [&](double k) { return std::sqrt(std::max(0.0, tt - 2.0 * k * tc + k * k * cc) / tt); };
  for (VxgiClipmap& clip : result.clipmaps) {
    clip.diffuse_scale = float(scale);
    clip.calibration_error = float(rel_rms(scale));
    clip.calibration_points = uint32_t(points.size());
  }
  result.stats.uncalibrated_error = float(rel_rms(1.0));
  ctx.note("vxgi: diffuse cones calibrated against the path tracer at " + std::to_string(points.size()) +
           " open-space points: scale " + std::to_string(scale) + ", relative RMS " + std::to_string(rel_rms(1.0)) +
           " before, " + std::to_string(rel_rms(scale)) + " after");
  return Status::ok();
}

}  // namespace gibake
