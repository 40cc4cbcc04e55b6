// std430 structs shared by C++ (bake/vulkan/*.cpp) and the GLSL kernels (kernels/shaders/*.comp).
// Every member is a 16-byte vector so std430 and C++ agree without padding rules; the C++ side
// static_asserts sizes and offsets. Included by GLSL through glslc -I kernels/shaders.
#ifndef GIBAKE_GPU_TYPES_H
#define GIBAKE_GPU_TYPES_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <cstring>
namespace gibake::gpu {
struct alignas(16) vec4 { float x, y, z, w; };
struct alignas(16) uvec4 { uint32_t x, y, z, w; };
// A double the kernels stored as two 32-bit words (GLSL unpackDouble2x32: low word first).
inline double double_from_words(uint32_t lo, uint32_t hi) {
  const uint64_t bits = uint64_t(lo) | uint64_t(hi) << 32;
  double d;
  std::memcpy(&d, &bits, sizeof(d));
  return d;
}
#endif

#ifndef __cplusplus
// An invocation's index in a flat grid (vk::Dispatch::flat_groups): the host folds a line of
// workgroups into rows of at most maxComputeWorkGroupCount[0], so the last row may run past the count.
#define GIBAKE_FLAT_INVOCATION (gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x)
#endif

// A child reference: an inner node's index, or a leaf (kLeafBit) of `count` triangles starting at
// `first` in the triangle array: kLeafBit | (count - 1) << kLeafCountShift | first.
#define GPU_LEAF_BIT 0x80000000u
#define GPU_LEAF_COUNT_SHIFT 27u
#define GPU_LEAF_FIRST_MASK 0x07FFFFFFu
#define GPU_MAX_LEAF 16u
#define GPU_NO_ROOT 0xFFFFFFFFu
#define GPU_STACK 64

// Binary BVH node holding both children's boxes (tested together, nearer child first):
// c0_xy = (c0.lo.x, c0.hi.x, c0.lo.y, c0.hi.y), c1_xy likewise, z = (c0.lo.z, c0.hi.z, c1.lo.z,
// c1.hi.z), children.xy = child references. 64 bytes.
struct GpuBvhNode {
  vec4 c0_xy;
  vec4 c1_xy;
  vec4 z;
  uvec4 children;
};

// A triangle in leaf order: its three corners as the scene holds them (the watertight test needs
// the corners themselves: edges rounded per triangle would not meet their neighbours'). v0.w: the
// Scene triangle index (as uint bits); v1.w: 0 when opaque, else 1 + its index in the
// alpha-triangle array. 48 bytes.
struct GpuTriangle {
  vec4 v0;
  vec4 v1;
  vec4 v2;
};

// What an alpha test needs at a masked triangle: uvs and vertex-colour alphas of its corners,
// and its material. 48 bytes.
struct GpuAlphaTriangle {
  vec4 uv01;     // u0 v0 u1 v1
  vec4 uv2_a01;  // u2 v2 alpha0 alpha1
  uvec4 a2_mat;  // x: alpha2 (float bits), y: material index
};

// A material as the kernels read it. 64 bytes.
struct GpuMaterial {
  vec4 base_color;  // linear factor, alpha in w
  vec4 xform;       // base-colour texture transform: offset.xy, scale.zw
  vec4 params;      // x: rotation, y: alpha cutoff (< 0: opaque), z: has_transform
  uvec4 tex;        // x: base-colour texture (GPU_NO_TEXTURE: none), y: double sided
};
#define GPU_NO_TEXTURE 0xFFFFFFFFu

// An RGBA8 texture in the texel pool. 16 bytes.
struct GpuTexture {
  uvec4 info;  // x: first texel in the pool, y: width, z: height, w: wrap_s | wrap_t << 16
};

// A ray: origin and tmin, direction and tmax. 32 bytes.
struct GpuRay {
  vec4 org_tmin;
  vec4 dir_tmax;
};

// A closest hit: t (< 0: miss), Scene triangle, Embree barycentrics. 16 bytes.
struct GpuHit {
  vec4 t_tri_uv;  // x: t, y: triangle (uint bits), z: u, w: v
};

// Push constants of traverse.comp.
struct TraversePush {
  uvec4 params;  // x: ray count, y: mode (0 closest hit, 1 any hit), z: root reference
};

// --- the path-traced gather (path.comp) ---

// A vertex as shading reads it: position and u, normal (zero: none) and v, linear RGBA colour.
struct GpuVertex {
  vec4 pos_u;
  vec4 normal_v;
  vec4 color;
};

// A Scene triangle for shading: corner indices and material; texel density (sqrt(uv area / world
// area), bake/scene/texture_lod.h), emitter area density (EmitterTable::pdf_area), alpha slot (uint
// bits), the widest footprint in uv (TextureLod::max_uv_width).
struct GpuShadeTri {
  uvec4 idx_mat;
  vec4 extra;
};

// A material for shading (metallic/roughness ignored: Lambertian, as on the CPU).
struct GpuShadeMaterial {
  vec4 base_color;  // linear factor
  vec4 base_xform;  // base-colour texture transform: offset.xy, scale.zw
  vec4 emissive;    // factor rgb, w: strength (0 when the material is not emissive)
  vec4 emit_xform;  // emissive texture transform
  vec4 rot;         // x: base rotation, y: base has_transform, z: emissive rotation, w: emissive has_transform
  uvec4 tex;        // x: base-colour texture, y: emissive texture (GPU_NO_TEXTURE: none), z: double sided,
                    // w: transmission factor (float bits; Material::transmission)
  vec4 trans_xform; // transmission texture transform
  uvec4 trans_tex;  // x: transmission texture (GPU_NO_TEXTURE: none), y: rotation (float bits), z: has_transform
};

// A texture's mip chain: x: first entry in the level table, y: levels (0: no pixels), z: wrap_s |
// wrap_t << 16. Level table entries: x: first texel in the pool, y: width, z: height.
struct GpuShadeTexture {
  uvec4 info;
};
struct GpuTexLevel {
  uvec4 info;
};

// kernels::ShadeLight as is.
struct GpuLight {
  vec4 pos_range;
  vec4 dir_type;
  vec4 color;
  vec4 cone;
};

// A probe ray of the path gather: origin, direction, its random key (rng_hash(seed, probe, pass,
// ray), low and high words), then its probe's emitter-sample shift key (rng_hash(seed, probe, pass,
// kernels::kProbeLightShiftRay), low and high words).
struct GpuPathRay {
  vec4 org;
  vec4 dir;
  uvec4 key;
};

// What path.comp returns per probe ray: a kernels::HitRecord's dir_t, normal_kind, radiance0 and
// albedo, and counts (shadow rays, bounce rays, back face 0/1).
struct GpuPathOut {
  vec4 dir_t;
  vec4 normal_kind;
  vec4 radiance;
  vec4 albedo;
  uvec4 counts;
};

// Settings of one path dispatch (a storage buffer, read by every invocation).
struct GpuPathParams {
  uvec4 counts;   // x: rays, y: BVH root, z: lights, w: emitters
  uvec4 flags;    // x: random light, y: bounces, z: roulette depth, w: the last bounce ray is useful
  vec4 sky;       // constant radiance rgb, w: scale
  // x: width, y: height (0: constant sky); z: mode (0 path gather, 1 probe feedback, 2 the check's reference paths); w: 1
  // = each probe ray is paired with an emitter sample from the probe (bake/trace/path_gather.h)
  uvec4 sky_map;
  // x: cone spread, y: shadow bias, z: 1 when a triangle's material transmits (glass), w: the share
  // of the probe's light samples that go to the sky map
  vec4 misc;
};

// A probe of a chunk whose rays raygen.comp makes: origin (w unused), the rows of its rotation
// (kernels::random_rotation, w unused), key.x: probe index, key.y: pass (batch). 80 bytes.
struct GpuRayGenProbe {
  vec4 org;
  vec4 rot0;
  vec4 rot1;
  vec4 rot2;
  uvec4 key;
};
// Push constants of raygen.comp.
struct RayGenPush {
  uvec4 counts;  // x: rays of this dispatch, y: rays per probe, z: index in the chunk of its first ray
  uvec4 seed;    // x: low, y: high word of the bake's seed
  // counts.w: 0 = path rays (GpuPathRay, with keys), 1 = geometry rays (GpuRay: tmin 0, tmax
  // infinity, no keys), the relocation pass's layout for traverse.comp.
};

// --- relocation statistics (reloc_sums.comp) ---

// A Scene triangle as the relocation sums classify its hits: ng.xyz = cross(v1 - v0, v2 - v0)
// (the counter-clockwise side, as geometry_record computes it), ng.w: 1.0 when its material is
// double sided. 16 bytes.
struct GpuRelocTri {
  vec4 ng;
};
// Push constants of reloc_sums.comp.
struct RelocSumsPush {
  uvec4 counts;  // x: probes of the chunk, y: rays per probe, z: the window's first ray, w: its length
  vec4 params;   // x: threshold (m)
};
// One probe's relocation_sums: delta as doubles (low, high words of each), nearest front depth
// below the threshold (float bits), close flag. 32 bytes.
struct GpuRelocSums {
  uvec4 delta_xy;       // x, y: delta.x; z, w: delta.y
  uvec4 delta_z_close;  // x, y: delta.z; z: nearest (float bits); w: 1 = a front hit closer than the threshold
};
// Push constants of path.comp: where it also writes each ray's integration sample (GpuRaySample,
// integration_sample's rule) into the integration's device buffer.
struct PathPush {
  // x: 1 = write samples, y: the sample index of the dispatch's first ray (its index in the chunk),
  // z: 1 = briefs, w: rays per probe (with the probe's emitter samples, each ray's follows the
  // probe's rays in the samples)
  uvec4 samples;
  vec4 params;    // x: max distance (the depth of misses and the clamp)
};
// What the host reads of a path-gather ray whose sample stays on the device (statistics and ray
// test: radiance, t (-1 for a miss), kind; the counters), written instead of GpuPathOut. 32 bytes.
struct GpuPathBrief {
  vec4 radiance_t;  // radiance rgb, w: t
  uvec4 counts;     // x: shadow rays, y: bounce rays, z: back face 0/1, w: HitKind
};

// --- LPV propagation (lpv_scale.comp, lpv_propagate.comp): kernels::LpvCell as is ---
struct GpuLpvCell {
  vec4 r;  // L1 SH of one colour channel (kernels/lpv.h order)
  vec4 g;
  vec4 b;
};
// One face of lpv_face_table_export: Y(w), then solid angle, lobe0, lobe1, lobe_index.
struct GpuLpvFace {
  vec4 basis;
  vec4 params;
};
struct LpvPush {
  uvec4 dims;  // xyz: cells per axis, w: 1 when the geometry volume occludes this step
};

// --- voxel-GI diffuse cone queries (vxgi_diffuse.comp): a gibake_vxgi_volume's fields ---
struct GpuVxgiParams {
  vec4 grid_min_size;  // xyz: grid_min (m), w: voxel_size (m)
  uvec4 dims_levels;   // xyz: level-0 voxels per axis, w: mip levels
  vec4 sky_scale;      // xyz: sky radiance (cd/m^2), w: diffuse_scale
  uvec4 flags;         // x: 1 when the volume has an SDF, y: its first radiance element, z: its first SDF value, w: faces stored (6, or 22 with cone slices)
};

// --- integration of probe rays (integrate.comp): kernels::integrate_radiance / integrate_depth ---

// kernels::RaySample as is: unit direction and the depth recorded for visibility (misses at the
// max distance, back faces x 0.9), incident radiance (w unused). 32 bytes.
struct GpuRaySample {
  vec4 dir_depth;
  vec4 radiance;
};
// A probe of one dispatch: x: its first sample, y: its sample count, z: the Monte-Carlo norm
// 4pi/rays as float bits (computed on the host in double, as the CPU does), w: its rays, the
// samples that enter the depth moments (fewer than y when the rays' emitter samples follow them).
// acc: x: the probe's output slot (and accumulator slot); y: GPU_ACC_LOAD | GPU_ACC_STORE, resume
// the sums from the slot's accumulators and store them back (--target-error's passes).
struct GpuIntegrateProbe {
  uvec4 range;
  uvec4 acc;
};
#define GPU_ACC_LOAD 1u
#define GPU_ACC_STORE 2u
struct IntegratePush {
  uvec4 counts;  // x: probes, y: SH coefficients (1, 4 or 9), z: the window's first sample counted
                 // from each probe's first, w: its length (at most GPU_RAY_WINDOW)
  vec4 params;   // x: cos cutoff of the depth cone (pow(dot, 64) below min_weight is zero)
};
#define GPU_INTEGRATE_GROUP 256u
#define GPU_IRRADIANCE_TEXELS 64u
#define GPU_DEPTH_TEXELS 256u

#ifdef __cplusplus
static_assert(sizeof(GpuRaySample) == 32 && offsetof(GpuRaySample, radiance) == 16, "GpuRaySample layout");
static_assert(sizeof(GpuIntegrateProbe) == 32 && sizeof(IntegratePush) == 32, "integration layouts");
static_assert(sizeof(GpuVxgiParams) == 64, "GpuVxgiParams layout");
static_assert(sizeof(GpuLpvCell) == 48 && sizeof(GpuLpvFace) == 32 && sizeof(LpvPush) == 16, "LPV layouts");
static_assert(sizeof(GpuVertex) == 48 && sizeof(GpuShadeTri) == 32, "shading layouts");
static_assert(sizeof(GpuShadeMaterial) == 128 && offsetof(GpuShadeMaterial, tex) == 80 &&
                  offsetof(GpuShadeMaterial, trans_tex) == 112,
              "GpuShadeMaterial layout");
static_assert(sizeof(GpuLight) == 64 && sizeof(GpuPathRay) == 48 && sizeof(GpuPathOut) == 80, "path layouts");
static_assert(sizeof(GpuPathParams) == 80, "GpuPathParams layout");
static_assert(sizeof(GpuRayGenProbe) == 80 && offsetof(GpuRayGenProbe, key) == 64 && sizeof(RayGenPush) == 32 &&
                  sizeof(PathPush) == 32 && sizeof(GpuPathBrief) == 32,
              "ray generation layouts");
static_assert(sizeof(GpuRelocTri) == 16 && sizeof(RelocSumsPush) == 32, "relocation sums layouts");
static_assert(sizeof(GpuRelocSums) == 32 && offsetof(GpuRelocSums, delta_z_close) == 16, "GpuRelocSums layout");
static_assert(sizeof(GpuBvhNode) == 64 && offsetof(GpuBvhNode, children) == 48, "GpuBvhNode layout");
static_assert(sizeof(GpuTriangle) == 48 && offsetof(GpuTriangle, v2) == 32, "GpuTriangle layout");
static_assert(sizeof(GpuAlphaTriangle) == 48 && offsetof(GpuAlphaTriangle, a2_mat) == 32, "GpuAlphaTriangle layout");
static_assert(sizeof(GpuMaterial) == 64 && offsetof(GpuMaterial, tex) == 48, "GpuMaterial layout");
static_assert(sizeof(GpuTexture) == 16, "GpuTexture layout");
static_assert(sizeof(GpuRay) == 32 && offsetof(GpuRay, dir_tmax) == 16, "GpuRay layout");
static_assert(sizeof(GpuHit) == 16, "GpuHit layout");
static_assert(sizeof(TraversePush) == 16, "TraversePush layout");
}  // namespace gibake::gpu
#endif

// --- probe-feedback bounce passes (bounce_weights.comp, bounce_pass.comp), the twins of
// kernels::ddgi_probe_weights and the per-probe body of run_bounce_passes (bake/ddgi/bounce.cpp) ---
#ifdef __cplusplus
namespace gibake::gpu {
#endif

// A bouncing hit (bake::BounceHit) and the probe its ray left from. 48 bytes.
struct GpuBounceHit {
  vec4 dir_t;          // ray direction, hit distance
  vec4 normal_probe;   // shading normal facing the ray; w: probe index as a float (exact below 2^24)
  vec4 albedo;
};
// A probe as both kernels read it. position: where its rays left from; w 1 when inactive.
// range: x first hit in the chunk's hit buffer, y hit count, z norm 4pi/count and w scale
// count/rays (float bits, computed on the host as the CPU computes them). 48 bytes.
struct GpuBounceProbe {
  vec4 position;
  vec4 offset;  // relocation offset (the 8-probe sampler's corner positions add it)
  uvec4 range;
};
// kernels::ProbeWeights: up to 8 probes (GPU_BOUNCE_NO_PROBE ends the list) and their weights.
struct GpuProbeWeights {
  uvec4 probe_lo;
  uvec4 probe_hi;
  vec4 weight_lo;
  vec4 weight_hi;
};
// Push constants of both kernels (96 bytes).
struct BouncePush {
  vec4 grid_min;  // w: normal bias
  vec4 spacing;   // w: smooth back-face blend
  uvec4 counts;   // xyz: probes per axis, w: depth tile interior resolution
  uvec4 range;    // x: first hit (weights) or probe (pass), y: how many, z: SH coefficients, w: 1 = last pass
  vec4 params;    // x: energy_conservation / pi, y..w: SH irradiance band factors pi, 2pi/3, pi/4
  uvec4 window;   // pass: x: the window's first hit counted from each probe's first, y: its length
};
#define GPU_BOUNCE_NO_PROBE 0xFFFFFFFFu
#define GPU_BOUNCE_WEIGHTS_GROUP 64u
#define GPU_BOUNCE_PASS_GROUP 128u

#ifdef __cplusplus
static_assert(sizeof(GpuBounceHit) == 48 && offsetof(GpuBounceHit, albedo) == 32, "GpuBounceHit layout");
static_assert(sizeof(GpuBounceProbe) == 48 && offsetof(GpuBounceProbe, range) == 32, "GpuBounceProbe layout");
static_assert(sizeof(GpuProbeWeights) == 64 && offsetof(GpuProbeWeights, weight_lo) == 32, "GpuProbeWeights layout");
static_assert(sizeof(BouncePush) == 96 && offsetof(BouncePush, params) == 64, "BouncePush layout");
}  // namespace gibake::gpu
#endif

// --- per-probe statistics of the path gather (probe_stats.comp), reduced from the GpuPathBriefs on
// the device so that only these come back: the twins of TraceCounters, the ray test's misses and
// saw-light flag, and trace_stage.cpp's RunningStats (Welford over each ray's luminance in ray
// order, in double; doubles travel as packDouble2x32 word pairs to keep 16-byte vector members) ---
#ifdef __cplusplus
namespace gibake::gpu {
#endif

// One probe of a chunk. The kernel continues it batch after batch (a probe's rays may straddle
// path batches), so it is the state of a sequential loop, not a merge of partial results. 48 bytes.
struct GpuProbeStats {
  uvec4 counts;   // x: rays, y: shadow rays, z: bounce rays, w: back faces
  uvec4 test;     // x: misses, y: 1 when a ray brought light, z: nearest front t (float bits, -1: none)
  uvec4 welford;  // xy: mean, zw: m2 (double, low word first)
};
// Push constants of probe_stats.comp.
struct ProbeStatsPush {
  uvec4 range;   // x: chunk index of the batch's first ray, y: rays in the batch, z: rays per probe,
                 // w: bit 0: add each ray's paired emitter sample (binding 2) to its luminance;
                 // bit 1: resume every probe from the state in the buffer (--target-error's passes)
  uvec4 window;  // x: first ray of the window, counted from each probe's first ray; y: its length
};
#define GPU_PROBE_STATS_GROUP 64u
// The most rays (or, for integrate.comp, samples) one invocation walks in one dispatch: a probe's
// rays take as many dispatches as its windows. A shader loop's trip count then never grows with the
// rays of a probe (Mesa's llvmpipe ends every loop of an invocation after 65535 iterations in all).
#define GPU_RAY_WINDOW 16384u

#ifdef __cplusplus
static_assert(sizeof(GpuProbeStats) == 48 && offsetof(GpuProbeStats, welford) == 32, "GpuProbeStats layout");
static_assert(sizeof(ProbeStatsPush) == 32, "ProbeStatsPush layout");
}  // namespace gibake::gpu
#endif

// --- the reconstruction check's reference paths (path.comp mode 2, reference_sums.comp) ---
#ifdef __cplusplus
namespace gibake::gpu {
#endif

// One surface point whose paths the device makes and traces (bake/preview/reconstruction_check.cpp
// reference_path's twin): the paths' origin (offset off the surface), the shading normal they are
// cosine-distributed about, the geometric normal below which none is traced, the point's key and
// the check's path salt. 64 bytes.
struct GpuReferencePoint {
  vec4 origin;  // xyz, w unused
  vec4 n;       // xyz, w unused
  vec4 ng;      // xyz, w unused
  uvec4 key;    // xy: the point's key, zw: the salt (low word first)
};
// A point's paths summed in path order by reference_sums.comp: 80 bytes.
struct GpuReferenceSums {
  vec4 sum;        // xyz: radiance summed over the traced paths, w: luminance of the even half
  vec4 half_lum;   // x: luminance of the odd half; y: the same of the ended paths (`ended`)
  uvec4 counts;    // x, y: paths in each half, z: shadow rays, w: bounce rays
  uvec4 traced;    // x: paths traced (above the geometric surface)
  // With a probe field (path_probe_field.comp): xyz the same paths' radiance had each ended at its
  // first hit in the field, w: luminance of their even half.
  vec4 ended;
};
// Push constants of reference_sums.comp.
struct ReferenceSumsPush {
  uvec4 counts;  // x: points, y: paths per point, z: the window's first path, w: its length
  uvec4 flags;   // x: 1 = also sum each path's ended radiance (binding 2)
};

#ifdef __cplusplus
static_assert(sizeof(GpuReferencePoint) == 64 && sizeof(GpuReferenceSums) == 80 && sizeof(ReferenceSumsPush) == 32,
              "reference path layouts");
}  // namespace gibake::gpu
#endif

#endif  // GIBAKE_GPU_TYPES_H
