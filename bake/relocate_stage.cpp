#include "bake/relocate_stage.h"

#include <tbb/enumerable_thread_specific.h>

#include <array>

#include "bake/gpu_geometry.h"
#include "bake/probe_loop.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

struct Outputs {
  std::vector<float>& offsets;
  std::vector<uint8_t>& moved;
  std::vector<uint64_t>& rays;
};

// One probe's records of one pass: count its rays and move it.
void apply(const RelocateParams& params, int32_t p, const kernels::HitRecord* records, uint32_t count, uint64_t traced,
           Outputs& out) {
  out.rays[p] += traced;
  std::array<float, 3> off{out.offsets[p * 3], out.offsets[p * 3 + 1], out.offsets[p * 3 + 2]};
  if (relocate_probe(records, count, params, off)) {
    for (int a = 0; a < 3; ++a) out.offsets[p * 3 + a] = off[a];
    out.moved[p] = 1;
  }
}

void generate(const RelocationStage& st, int32_t p, int iter, float* dirs) {
  kernels::generate_probe_rays_from_set(st.fibonacci, st.seed, p, kRelocatePassBase + uint32_t(iter), st.rays, dirs);
}

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
  for_probes_waves(*st.arena, probes, ctx, "relocate", [&](int32_t p) {
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
  for (int iter = 0; iter < st.iterations; ++iter) {
    if (st.gpu) {
      GIBAKE_TRY(pass_gpu(st, probes, iter, out));
      ctx.report("relocate", double(iter + 1), double(st.iterations));
    } else {
      pass_cpu(st, probes, iter, ctx, out);
    }
  }
  return Status::ok();
}

}  // namespace gibake
