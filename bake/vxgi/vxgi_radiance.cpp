// Level-0 voxel radiance (vxgi_radiance in vxgi.h): rays into every face of every surface voxel,
// the path tracer's radiance at what they meet, and where that radiance is stored.
//
// Split sides (VxgiSettings::split_sides, the default): the radiance leaving one side of a surface
// is stored in the voxel half a voxel off the hit along that side's normal, so a voxel never holds
// the mean of a thin wall's lit and dark sides (its faces along the wall would, and oblique cones
// from the dark side read them: docs/BENCHMARKS.md, "Voxel GI"). A thin wall then
// takes two voxel layers, one per side, each opaque with the wall's coverage.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <unordered_map>

#include "bake/run/arena.h"
#include "bake/scene/emitters.h"
#include "bake/trace/path_gather.h"
#include "bake/vxgi/vxgi.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"

namespace gibake {
using kernels::float3;

namespace {

constexpr size_t kChunk = 64;  // surface voxels per work item (fixed: the bytes never depend on threads)
constexpr uint64_t kFaceStream = 0x7678676946616365ull;  // "vxgiFace": keeps voxel keys apart from probe keys

// Exit distance of a ray from inside-or-on the box [lo, hi] (slab test), plus a little.
float box_exit(const float3& o, const float3& d, const float lo[3], const float hi[3]) {
  float t = 1e30f;
  const float oc[3] = {o.x, o.y, o.z}, dc[3] = {d.x, d.y, d.z};
  for (int a = 0; a < 3; ++a) {
    if (dc[a] > 0.f) t = std::min(t, (hi[a] - oc[a]) / dc[a]);
    if (dc[a] < 0.f) t = std::min(t, (lo[a] - oc[a]) / dc[a]);
  }
  return std::max(t, 0.f);
}

struct FaceSum {
  float3 sum{0.f, 0.f, 0.f};
  uint32_t hits = 0;       // front faces (or double-sided)
  uint32_t back_hits = 0;  // backs of single-sided surfaces (black)
};

// Radiance of one face's hits, summed where it is stored (split sides): voxel `cell`, face `face`.
struct Deposit {
  size_t cell = 0;
  int face = 0;
  float3 sum{0.f, 0.f, 0.f};
  uint32_t hits = 0;
  float alpha = 0.f;  // coverage of the voxel whose surface it is
};

struct Tracer {
  const PathSetup& ps;
  const VoxelGrid& g;
  const VxgiSettings& s;
  uint32_t stream;
  bool split;

  // The rays of one face of one voxel (see vxgi_radiance in vxgi.h). Split: each hit is added to
  // `out` at the voxel half a voxel off the hit on the side the ray saw; else summed in the result.
  FaceSum trace_face(const SurfaceVoxel& sv, int face, TraceCounters& tc, std::vector<Deposit>& out) const {
    const int axis = face / 2;
    const float sign = face % 2 == 0 ? 1.f : -1.f;
    const float h = g.voxel_size, eps = 1e-4f * h;
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = g.origin[size_t(a)] + float(sv.ijk[a]) * h;
      hi[a] = lo[a] + h;
    }
    float3 inward{0.f, 0.f, 0.f};
    (&inward.x)[axis] = -sign;
    const uint64_t voxel = uint64_t(g.linear(sv.ijk[0], sv.ijk[1], sv.ijk[2]));
    const float alpha = std::min(std::max(sv.coverage, 0.f), 1.f);
    FaceSum fs;
    for (uint32_t r = 0; r < s.rays; ++r) {
      const uint64_t key = kernels::rng_hash(s.seed, voxel, kFaceStream + uint64_t(face) + 8 * uint64_t(stream), r);
      float o[3];
      for (int a = 0; a < 3; ++a) o[a] = lo[a] + kernels::rng_uniform(key, uint32_t(a)) * h;
      o[axis] = sign > 0.f ? hi[axis] + eps : lo[axis] - eps;
      const float3 org{o[0], o[1], o[2]};
      const float3 dir = kernels::sample_cosine_hemisphere(inward, kernels::rng_uniform(key, 3), kernels::rng_uniform(key, 4));
      const float tmax = box_exit(org, dir, lo, hi) + eps;
      float3 l;
      bool back = false;
      if (!split) {
        if (!trace_radiance_within(ps, org, dir, tmax, key, tc, l, back)) continue;
        if (back) {
          ++fs.back_hits;
        } else {
          fs.sum += l;
          ++fs.hits;
        }
        continue;
      }
      const TraceHit hit = ps.trace.prepared->intersect(org, dir, 0.f, tmax);  // where, and which side
      ++tc.rays;
      // The back of a single-sided surface is stored nowhere: nothing should see it (the inside of a
      // closed solid, the outside of a closed room), and black voxels there would darken the mips
      // of the front side by half; the front side's voxel is opaque and black towards it.
      if (hit.t < 0.f || !trace_radiance_within(ps, org, dir, tmax, key, tc, l, back) || back) continue;
      const float3 side = hit.front ? hit.ng : -hit.ng;  // the normal of the side the ray saw
      const float3 at = org + dir * hit.t + side * (0.5f * h);
      int32_t ijk[3];
      for (int a = 0; a < 3; ++a) {
        const float v = std::floor(((&at.x)[a] - g.origin[size_t(a)]) / h);
        ijk[a] = int32_t(std::min(std::max(v, 0.f), float(g.dims[size_t(a)] - 1)));
      }
      const size_t cell = size_t(g.linear(ijk[0], ijk[1], ijk[2]));
      auto it = std::find_if(out.begin(), out.end(), [&](const Deposit& d) { return d.cell == cell && d.face == face; });
      if (it == out.end()) it = out.insert(out.end(), Deposit{cell, face, {0.f, 0.f, 0.f}, 0u, alpha});
      it->sum += l;
      ++it->hits;
    }
    return fs;
  }
};

// Radiance of face f (unsplit): the mean of its front hits; black when its rays met only the backs
// of single-sided surfaces and the voxel's surface faces away from f; otherwise (no hits, or a face
// along the surface) the mean of the voxel's front hits over all faces. The last case matters where
// a surface lies on a voxel boundary: the conservative voxelizer marks the voxels on both sides,
// and the far one's faces along the surface would otherwise be black and darken the mips by half
// where cones see the surface at an angle.
float3 face_radiance(const SurfaceVoxel& sv, int f, const FaceSum& face, const FaceSum& all) {
  if (face.hits) return face.sum * (1.f / float(face.hits));
  const float along = (f % 2 == 0 ? 1.f : -1.f) * sv.normal[f / 2];
  if (face.back_hits && along < -0.5f) return {0.f, 0.f, 0.f};
  return all.hits ? all.sum * (1.f / float(all.hits)) : float3{0.f, 0.f, 0.f};
}

// Neighbour of voxel `ijk` across a face is inside a closed solid (the face is never seen).
bool faces_solid(const VoxelGrid& g, const std::vector<uint8_t>& solid, const int32_t ijk[3], int face) {
  int32_t n[3] = {ijk[0], ijk[1], ijk[2]};
  n[face / 2] += face % 2 == 0 ? 1 : -1;
  for (int a = 0; a < 3; ++a)
    if (n[a] < 0 || n[a] >= g.dims[size_t(a)]) return false;
  return solid[size_t(g.linear(n[0], n[1], n[2]))] != 0;
}

void store(std::vector<float>& level0, size_t cells, size_t cell, int f, const float3& l, float alpha) {
  float* o = level0.data() + (size_t(f) * cells + cell) * 4;
  o[0] = alpha * l.x;
  o[1] = alpha * l.y;
  o[2] = alpha * l.z;
  o[3] = alpha;
}

// Split sides: the deposits summed per voxel (in the fixed chunk order), then each voxel's faces:
// a face without deposits is black when the opposite face has some (it looks out through the back
// of the surface stored there: a thin wall's lit layer shows nothing towards the dark side), else
// it takes the mean of the voxel's others; alpha is the largest coverage of the surfaces stored there.
// Voxels that receive nothing stay empty, surface voxels too: the surface's sides are stored (and
// block) in their neighbours.
void resolve_deposits(const VoxelGrid& g, const std::vector<uint8_t>& solid, const std::vector<std::vector<Deposit>>& chunks,
                      std::vector<float>& level0) {
  struct Acc {
    float3 sum[kVxgiFaces];
    uint32_t hits[kVxgiFaces] = {};
    float alpha = 0.f;
  };
  const size_t cells = solid.size();
  std::unordered_map<size_t, Acc> acc;
  for (const auto& chunk : chunks)
    for (const Deposit& d : chunk) {
      Acc& a = acc[d.cell];
      a.sum[d.face] += d.sum;
      a.hits[d.face] += d.hits;
      a.alpha = std::max(a.alpha, d.alpha);
    }
  for (const auto& [cell, a] : acc) {
    if (solid[cell]) continue;
    float3 all{0.f, 0.f, 0.f};
    uint32_t all_hits = 0;
    for (int f = 0; f < kVxgiFaces; ++f) {
      all += a.sum[f];
      all_hits += a.hits[f];
    }
    const int32_t ijk[3] = {int32_t(cell % size_t(g.dims[0])), int32_t((cell / size_t(g.dims[0])) % size_t(g.dims[1])),
                            int32_t(cell / (size_t(g.dims[0]) * size_t(g.dims[1])))};
    for (int f = 0; f < kVxgiFaces; ++f) {
      float3 l{0.f, 0.f, 0.f};
      if (faces_solid(g, solid, ijk, f)) l = {0.f, 0.f, 0.f};
      else if (a.hits[f]) l = a.sum[f] * (1.f / float(a.hits[f]));
      else if (all_hits && !a.hits[f ^ 1]) l = all * (1.f / float(all_hits));
      store(level0, cells, cell, f, l, a.alpha);
    }
  }
}

}  // namespace

Status vxgi_radiance(const VoxelGrid& g, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                     const Sky& sky, const VxgiSettings& s, const Context& ctx, std::vector<float>& level0,
                     VxgiStats& stats, uint32_t stream) {
  const size_t cells = size_t(g.dims[0]) * size_t(g.dims[1]) * size_t(g.dims[2]);
  level0.assign(size_t(kVxgiFaces) * cells * 4, 0.f);
  const std::vector<uint8_t> solid = vxgi_solid_interior(g);
  for (size_t c = 0; c < cells; ++c) {
    if (!solid[c]) continue;
    for (int f = 0; f < kVxgiFaces; ++f) level0[(size_t(f) * cells + c) * 4 + 3] = 1.f;
    ++stats.interior_voxels;
  }
  stats.surface_voxels = g.surface.size();
  EmitterTable emitters(prepared.scene());
  const PathSetup ps = make_path_setup(prepared, lights, sky, emitters, s.seed, s.bounces);
  const Tracer tracer{ps, g, s, stream, s.split_sides};
  const size_t chunks = (g.surface.size() + kChunk - 1) / kChunk;
  std::vector<TraceCounters> counters(chunks);
  std::vector<uint64_t> traced(chunks, 0), skipped(chunks, 0);
  std::vector<std::vector<Deposit>> deposits(chunks);
  std::atomic<size_t> done{0};
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] {
    tbb::parallel_for(size_t(0), chunks, [&](size_t chunk) {
      const size_t end = std::min(g.surface.size(), (chunk + 1) * kChunk);
      std::vector<Deposit> local;
      for (size_t i = chunk * kChunk; i < end; ++i) {
        const SurfaceVoxel& sv = g.surface[i];
        const size_t cell = size_t(g.linear(sv.ijk[0], sv.ijk[1], sv.ijk[2]));
        FaceSum faces[kVxgiFaces];
        FaceSum all;
        bool hidden[kVxgiFaces] = {};
        for (int f = 0; f < kVxgiFaces; ++f) {
          if (faces_solid(g, solid, sv.ijk, f)) {
            hidden[f] = true;
            ++skipped[chunk];
            continue;
          }
          local.clear();
          faces[f] = tracer.trace_face(sv, f, counters[chunk], local);
          deposits[chunk].insert(deposits[chunk].end(), local.begin(), local.end());
          ++traced[chunk];
          all.sum += faces[f].sum;
          all.hits += faces[f].hits;
        }
        if (s.split_sides) continue;
        const float alpha = std::min(std::max(sv.coverage, 0.f), 1.f);
        for (int f = 0; f < kVxgiFaces; ++f)
          store(level0, cells, cell, f, hidden[f] ? float3{0.f, 0.f, 0.f} : face_radiance(sv, f, faces[f], all), alpha);
      }
      ctx.report("vxgi radiance", double(done += end - chunk * kChunk), double(g.surface.size()));
    });
  });
  if (s.split_sides) resolve_deposits(g, solid, deposits, level0);
  for (size_t c = 0; c < chunks; ++c) {
    stats.rays += counters[c].rays;
    stats.shadow_rays += counters[c].shadow_rays;
    stats.bounce_rays += counters[c].bounce_rays;
    stats.faces_traced += traced[c];
    stats.faces_skipped += skipped[c];
  }
  return Status::ok();
}

}  // namespace gibake
