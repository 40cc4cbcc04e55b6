#include "bake/ddgi/relocate_stage.h"

#include <tbb/enumerable_thread_specific.h>

#include <array>
#include <memory>

#include "bake/run/probe_loop.h"
#include "bake/vulkan/geometry.h"
#include "bake/vulkan/relocate.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

struct Outputs {
  std::vector<float>& offsets;
  std::vector<uint8_t>& moved;
  std::vector<uint64_t>& rays;
};

// One probe's sums of one pass: count its rays and move it.
void apply(const RelocateParams& params, int32_t p, const RelocationSums& sums, uint64_t traced, Outputs& out) {
  out.rays[p] += traced;
  std::array<float, 3> off{out.offsets[p * 3], out.offsets[p * 3 + 1], out.offsets[p * 3 + 2]};
  if (apply_relocation(sums, params, off)) {
    for (int a = 0; a < 3; ++a) out.offsets[p * 3 + a] = off[a];
    out.moved[p] = 1;
  }
}

void apply(const RelocateParams& params, int32_t p, const kernels::HitRecord* records, uint32_t count, uint64_t traced,
           Outputs& out) {
  apply(params, p, relocation_sums(records, count, params.threshold), traced, out);
}

void generate(const RelocationStage& st, int32_t p, int iter, float* dirs) {
  kernels::generate_probe_rays_from_set(st.fibonacci, st.seed, p, kRelocatePassBase + uint32_t(iter), st.rays, dirs);
}

// Rays, hits and sums stay on the device; every ray is traced, so each probe counts st.rays.
Status pass_gpu_sums(const RelocationStage& st, GpuRelocation& reloc, const std::vector<int32_t>& probes, int iter,
                     Outputs& out) {
  std::vector<RelocationSums> sums;
  GIBAKE_TRY(reloc.sums(probes, st.seed, kRelocatePassBase + uint32_t(iter), st.position, st.params.threshold, sums));
  for (size_t i = 0; i < probes.size(); ++i) apply(st.params, probes[i], sums[i], st.rays, out);
  return Status::ok();
}

// The per-ray path: every ray and hit crosses the bus (ray capture, devices without doubles).
Status pass_gpu(const RelocationStage& st, const std::vector<int32_t>& probes, int iter, Outputs& out) {
  GeometryRays g;
  g.rays_per_probe = st.rays;
  g.origin = st.position;
  g.directions = [&](int32_t p, float* dirs) { generate(st, p, iter, dirs); };
  g.done = [&](int32_t p, const kernels::HitRecord* records, const TraceCounters& tc) {
    apply(st.params, p, records, st.rays, tc.rays, out);
  };
  g.capture = st.capture;
  return trace_geometry_gpu(*st.gpu, *st.scene, probes, g);
}

void pass_cpu(const RelocationStage& st, const std::vector<int32_t>& probes, int iter, const Context& ctx,
              Outputs& out) {
  struct Scratch {
    std::vector<float> dirs;
    std::vector<kernels::HitRecord> hits;
  };
  tbb::enumerable_thread_specific<Scratch> scratch;
  TraceSetup geo = st.setup;
  geo.shade = false;
  for_probes_reporting(*st.arena, probes, ctx, "relocate", [&](int32_t p) {
    Scratch& sc = scratch.local();
    sc.dirs.resize(size_t(st.rays) * 3);
    sc.hits.resize(st.rays);
    generate(st, p, iter, sc.dirs.data());
    TraceCounters tc;
    trace_probe_rays(geo, st.position(p), p, kRelocatePassBase + uint32_t(iter), sc.dirs.data(), st.rays,
                     sc.hits.data(), tc, st.capture ? &(*st.capture)[p] : nullptr);
    apply(st.params, p, sc.hits.data(), st.rays, tc.rays, out);
  });
}

}  // namespace

Status relocate_probes(const RelocationStage& st, const std::vector<int32_t>& probes, const Context& ctx,
                       std::vector<float>& offsets, std::vector<uint8_t>& moved, std::vector<uint64_t>& rays) {
  Outputs out{offsets, moved, rays};
  std::unique_ptr<GpuRelocation> reloc;  // null: the per-ray path
  if (st.gpu && !st.capture) GIBAKE_TRY(GpuRelocation::create(*st.gpu, *st.scene, st.fibonacci, st.rays, reloc));
  for (int iter = 0; iter < st.iterations; ++iter) {
    if (st.gpu) {
      GIBAKE_TRY(reloc ? pass_gpu_sums(st, *reloc, probes, iter, out) : pass_gpu(st, probes, iter, out));
      ctx.report("relocate", double(iter + 1), double(st.iterations));
    } else {
      pass_cpu(st, probes, iter, ctx, out);
    }
  }
  return Status::ok();
}

}  // namespace gibake
