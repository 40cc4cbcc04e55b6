// gibake DDGI sampler for shaders: irradiance E(P, N) in lux from one DDGI volume of a gibake bake
// file, the same operations in the same order as the loader's CPU sampler
// (gibake::loader::DdgiVolume::sample_irradiance, io/loader/src/sampler.cpp; docs/FORMAT.md "CPU
// sampler" and "GLSL sampler"). GLSL 450, no extensions; tests/vulkan/ddgi_sample_glsl_test.cpp
// checks it against the CPU sampler on Mesa's lavapipe.
//
// Use:
//   1. Fill a GibakeDdgiVolume from the file's gibake_ddgi_volume (C++: DdgiVolume::glsl_volume()
//      gives its 96 bytes, the same in std140 and std430) and put it in a uniform or storage buffer.
//   2. Say how the probe data is read, in one of two ways, before `#include "gibake/ddgi_sample.glsl"`:
//      a. Define four accessors, and optionally two more (macros; `v` is the GibakeDdgiVolume passed to
//         the sampler, free for an engine that keeps several volumes to pick one, e.g. by v.engine.x):
//           vec3 GIBAKE_DDGI_SH(v, uint probe, uint coefficient)  RGB of SH coefficient (cd/m^2)
//           uint GIBAKE_DDGI_STATE(v, uint probe)                 gibake_probe_state; 0 without states
//           vec3 GIBAKE_DDGI_OFFSET(v, uint probe)                relocation offset (m); 0 without offsets
//           vec2 GIBAKE_DDGI_DEPTH(v, ivec2 texel)                depth atlas texel: mean (m), mean^2
//           vec3 GIBAKE_DDGI_IRRADIANCE(v, ivec2 texel)           optional: irradiance atlas texel RGB (lux;
//                                                                 an RGB9E5 atlas's as stored, the sampler
//                                                                 multiplying by v.spacing.w)
//           uint GIBAKE_DDGI_SLOT(v, uint probe)                  optional: word `probe` of a sparse
//                                                                 volume's ddgi_probe_slots section
//         `probe` in the first three is the probe's index in the per-probe sections: its index in
//         the grid (x + X*(y + Y*z)), or in a sparse volume (format 1.5, bit 1 of v.atlas.w) the slot
//         GIBAKE_DDGI_SLOT gives (0xFFFFFFFF: not stored, inactive). Without GIBAKE_DDGI_SLOT a
//         sparse volume has no probe the sampler reads (it has no answer; a blend skips it).
//         e.g. `#define GIBAKE_DDGI_DEPTH(v, t) texelFetch(depthAtlas, t, 0).xy` for an RG texture.
//         Return the values the file holds (f16 converted exactly, no filtering): the sampler does
//         its own bilinear filtering in the CPU's order. Without GIBAKE_DDGI_IRRADIANCE the sampler
//         takes every probe's irradiance from its SH, as with use_irradiance_atlas false, and then
//         differs from the CPU's default (the atlas) wherever the volume has an irradiance atlas.
//         gibake_ddgi_atlas_width(v, interior) gives an atlas's width in texels (interior v.atlas.x
//         for the depth atlas, gibake_ddgi_irradiance_tile(v) for the irradiance atlas).
//      b. Or `#define GIBAKE_DDGI_SECTION_BUFFERS` (optionally GIBAKE_DDGI_SET, default 0, Vulkan only,
//         and GIBAKE_DDGI_BINDING, default 0): the include declares six readonly std430 buffers at
//         bindings BINDING+0..5 holding the ddgi_sh, ddgi_states, ddgi_offsets, ddgi_depth,
//         ddgi_irradiance and ddgi_probe_slots section payloads byte for byte as the file stores them (any element format;
//         upload each payload padded with zeros to a multiple of 4 bytes; bind any 4-byte buffer for
//         an absent section). One volume per shader this way.
//   3. Call gibake_ddgi_irradiance(volume, P, N) (or with GibakeSampleOptions) with world-space P
//      (metres) and unit N: RGB irradiance in lux, >= 0. Multiply by albedo / pi for diffuse radiance.
//   4. Several volumes in one file (accessors only): also define GIBAKE_DDGI_VOLUME(i), the i-th
//      volume in the loader's BakeFile::ddgi_priority() order, and call
//      gibake_ddgi_blended_irradiance(count, P, N[, options, out inside]): the volumes blended as the
//      loader's BakeFile::sample_ddgi blends them (docs/FORMAT.md "Several volumes").
// Example (accessors over an engine's own buffers, one volume; samples/consumer/ddgi_shading.frag
// is a complete one over every volume of a file, through its index):
//   #define GIBAKE_DDGI_SH(v, p, c) sh_rgb[(p) * uint((v).counts.w) + (c)].rgb
//   #define GIBAKE_DDGI_STATE(v, p) states[p]
//   #define GIBAKE_DDGI_OFFSET(v, p) offsets[p].xyz
//   #define GIBAKE_DDGI_DEPTH(v, t) texelFetch(depth_atlas, t, 0).xy
//   #define GIBAKE_DDGI_IRRADIANCE(v, t) texelFetch(irradiance_atlas, t, 0).rgb
//   #include "gibake/ddgi_sample.glsl"
//   vec3 e = gibake_ddgi_irradiance(volume, world_position, normalize(world_normal));  // lux
//   colour.rgb = albedo * e / 3.14159265;  // pass the unbiased point: the sampler adds the normal bias
// Arithmetic is `precise` where the CPU's rounding matters (no fused multiply-adds the CPU does not
// do); divisions and square roots are as exact as the device makes them.
#ifndef GIBAKE_DDGI_SAMPLE_GLSL
#define GIBAKE_DDGI_SAMPLE_GLSL

// One DDGI volume (gibake_ddgi_volume, format.h); vec4-aligned so std140 and std430 agree.
struct GibakeDdgiVolume {
  vec4 grid_min;  // xyz: world position of probe (0,0,0) before relocation, metres
  vec4 spacing;   // xyz: metres; 0 on a one-probe axis; w: an RGB9E5 irradiance atlas's
                  // irradiance_scale (its texels times w are lux), else 0
  ivec4 counts;   // xyz: probes per axis; w: sh_coefficients (4 or 9)
  uvec4 atlas;    // x: depth_tile, y: tile_border, z: atlas_planes_per_row (0 means Y; a sparse
                  // volume's atlas_tiles_per_row); w: bit 0 set with a depth atlas, bit 1 for a sparse
                  // volume, bits 8-23 irradiance_tile (0 without an irradiance atlas)
  uvec4 formats;  // element formats (format.h) of x: ddgi_sh, y: ddgi_states (0: none), z: ddgi_depth;
                  // w: bit 0 set with ddgi_offsets, bits 8-15 the ddgi_irradiance format (0: none).
                  // Formats are read only by the GIBAKE_DDGI_SECTION_BUFFERS accessors
  uvec4 engine;   // free for the includer (e.g. which volume's data); the sampler never reads it
};

// gibake::loader::SampleOptions, with the same defaults (gibake_default_sample_options()).
struct GibakeSampleOptions {
  float smooth_backface;    // 1: wrap-shading back-face weight; 0: hard saturate(dot(dir, N))
  float normal_bias;        // metres
  float normal_bias_cells;  // of the smallest probe spacing; the bias is the larger of the two
  float variance_floor;     // m^2, lower bound of the Chebyshev variance
  float min_weight;         // floor of back-face x visibility weight
  bool use_visibility;      // Chebyshev test when the volume has a depth atlas
  // A probe's irradiance from its irradiance atlas tile when the volume has one and
  // GIBAKE_DDGI_IRRADIANCE is defined (each texel the cosine-weighted mean of the probe's rays around
  // its normal), else from its SH. The SH's two bands ring: a bright source below a surface's horizon
  // (a sunlit floor seen from a probe beside it) reaches normals that cannot see it, and in sunlit
  // scenes that is the largest error of the SH. false: always the SH.
  bool use_irradiance_atlas;
  // A probe behind the surface's tangent plane (cosine c < 0 to it) weighs saturate(1 + c /
  // behind_fade) of its back-face weight: its light is the surface's far side. 0: off.
  float behind_fade;
};

GibakeSampleOptions gibake_default_sample_options() {
  return GibakeSampleOptions(1.0, 0.001, 0.3, 1e-4, 1e-6, true, true, 0.2);
}

// Interior texels a side of the irradiance atlas's tiles; 0 when the volume has no irradiance atlas.
uint gibake_ddgi_irradiance_tile(GibakeDdgiVolume v) { return (v.atlas.w >> 8u) & 0xFFFFu; }

// A sparse volume (format 1.5) stores only some probes, each at its slot.
bool gibake_ddgi_sparse(GibakeDdgiVolume v) { return (v.atlas.w & 2u) != 0u; }

// Width in texels of an atlas whose tiles have `interior` texels a side (format.h's layout: X
// columns of tiles for each of the k planes of a band; a sparse volume's T tiles a row).
uint gibake_ddgi_atlas_width(GibakeDdgiVolume v, uint interior) {
  const uint k = v.atlas.z != 0u ? v.atlas.z : uint(v.counts.y);
  const uint tiles = gibake_ddgi_sparse(v) ? v.atlas.z : uint(v.counts.x) * k;
  return tiles * (interior + 2u * v.atlas.y);
}

// A GIBAKE_FORMAT_RGB9E5 word (format 1.5) as the loader's rgb9e5_to_float decodes it: 9-bit
// mantissas, a shared 5-bit exponent, value = m * 2^(e - 24), exact. For an engine that reads the
// irradiance section's words itself; an E5B9G9R9_UFLOAT texture's texelFetch gives the same.
vec3 gibake_rgb9e5_to_float(uint w) {
  const int e = int(w >> 27u) - 24;
  return vec3(ldexp(float(w & 0x1FFu), e), ldexp(float((w >> 9u) & 0x1FFu), e), ldexp(float((w >> 18u) & 0x1FFu), e));
}

#define GIBAKE_PROBE_ACTIVE 0u
#define GIBAKE_PROBE_INACTIVE 1u
#define GIBAKE_PROBE_SKY_ONLY 2u
// docs/FORMAT.md "Several volumes" (format.h's GIBAKE_DDGI_FULL_SIGHT).
#define GIBAKE_DDGI_FULL_SIGHT 0.05

#ifdef GIBAKE_DDGI_SECTION_BUFFERS
#ifndef GIBAKE_DDGI_SET
#define GIBAKE_DDGI_SET 0
#endif
#ifndef GIBAKE_DDGI_BINDING
#define GIBAKE_DDGI_BINDING 0
#endif
// Descriptor sets are Vulkan's (GL_KHR_vulkan_glsl defines VULKAN); OpenGL has bindings only.
#ifdef VULKAN
#define GIBAKE_DDGI_LAYOUT(b) layout(std430, set = GIBAKE_DDGI_SET, binding = GIBAKE_DDGI_BINDING + b)
#else
#define GIBAKE_DDGI_LAYOUT(b) layout(std430, binding = GIBAKE_DDGI_BINDING + b)
#endif
GIBAKE_DDGI_LAYOUT(0) readonly buffer GibakeDdgiShSection { uint gibake_sh_words[]; };
GIBAKE_DDGI_LAYOUT(1) readonly buffer GibakeDdgiStatesSection { uint gibake_state_words[]; };
GIBAKE_DDGI_LAYOUT(2) readonly buffer GibakeDdgiOffsetsSection { uint gibake_offset_words[]; };
GIBAKE_DDGI_LAYOUT(3) readonly buffer GibakeDdgiDepthSection { uint gibake_depth_words[]; };
GIBAKE_DDGI_LAYOUT(4) readonly buffer GibakeDdgiIrradianceSection { uint gibake_irradiance_words[]; };
GIBAKE_DDGI_LAYOUT(5) readonly buffer GibakeDdgiSlotsSection { uint gibake_slot_words[]; };

// Element formats (format.h) the sections may have.
#define GIBAKE_FORMAT_F32 2u
#define GIBAKE_FORMAT_F16 3u
#define GIBAKE_FORMAT_U8 5u
#define GIBAKE_FORMAT_U32 6u
#define GIBAKE_FORMAT_RGBA16F 7u
#define GIBAKE_FORMAT_RGBA32F 8u
#define GIBAKE_FORMAT_RG16F 9u
#define GIBAKE_FORMAT_RGB9E5 13u

// Element `i` of an f32 or f16 array stored as little-endian words (halves convert exactly).
float gibake_section_float(uint word, uint i, bool half_format) {
  return half_format ? unpackHalf2x16(word)[i & 1u] : uintBitsToFloat(word);
}

vec3 gibake_section_sh(GibakeDdgiVolume v, uint probe, uint coefficient) {
  const uint first = (probe * uint(v.counts.w) + coefficient) * 3u;
  const bool h = v.formats.x == GIBAKE_FORMAT_F16;
  vec3 rgb;
  for (uint k = 0u; k < 3u; ++k) {
    const uint i = first + k;
    rgb[k] = gibake_section_float(gibake_sh_words[h ? i >> 1u : i], i, h);
  }
  return rgb;
}

uint gibake_section_state(GibakeDdgiVolume v, uint probe) {
  if (v.formats.y == GIBAKE_FORMAT_U8) return (gibake_state_words[probe >> 2u] >> (8u * (probe & 3u))) & 0xFFu;
  if (v.formats.y == GIBAKE_FORMAT_U32) return gibake_state_words[probe];
  return GIBAKE_PROBE_ACTIVE;
}

vec3 gibake_section_offset(GibakeDdgiVolume v, uint probe) {
  if ((v.formats.w & 1u) == 0u) return vec3(0.0);
  return vec3(uintBitsToFloat(gibake_offset_words[probe * 3u]), uintBitsToFloat(gibake_offset_words[probe * 3u + 1u]),
              uintBitsToFloat(gibake_offset_words[probe * 3u + 2u]));
}

vec2 gibake_section_depth(GibakeDdgiVolume v, ivec2 texel) {
  const uint t = uint(texel.y) * gibake_ddgi_atlas_width(v, v.atlas.x) + uint(texel.x);
  if (v.formats.z == GIBAKE_FORMAT_RG16F) return unpackHalf2x16(gibake_depth_words[t]);
  return vec2(uintBitsToFloat(gibake_depth_words[2u * t]), uintBitsToFloat(gibake_depth_words[2u * t + 1u]));
}

// RGB of an irradiance atlas texel: RGBA16F (two words a texel), RGBA32F (four) or RGB9E5 (one).
vec3 gibake_section_irradiance(GibakeDdgiVolume v, ivec2 texel) {
  const uint t = uint(texel.y) * gibake_ddgi_atlas_width(v, gibake_ddgi_irradiance_tile(v)) + uint(texel.x);
  if (((v.formats.w >> 8u) & 0xFFu) == GIBAKE_FORMAT_RGB9E5) return gibake_rgb9e5_to_float(gibake_irradiance_words[t]);
  if (((v.formats.w >> 8u) & 0xFFu) == GIBAKE_FORMAT_RGBA16F) {
    const vec2 rg = unpackHalf2x16(gibake_irradiance_words[2u * t]);
    return vec3(rg, unpackHalf2x16(gibake_irradiance_words[2u * t + 1u]).x);
  }
  return vec3(uintBitsToFloat(gibake_irradiance_words[4u * t]), uintBitsToFloat(gibake_irradiance_words[4u * t + 1u]),
              uintBitsToFloat(gibake_irradiance_words[4u * t + 2u]));
}

#define GIBAKE_DDGI_SH(v, probe, coefficient) gibake_section_sh(v, probe, coefficient)
#define GIBAKE_DDGI_STATE(v, probe) gibake_section_state(v, probe)
#define GIBAKE_DDGI_OFFSET(v, probe) gibake_section_offset(v, probe)
#define GIBAKE_DDGI_DEPTH(v, texel) gibake_section_depth(v, texel)
#define GIBAKE_DDGI_IRRADIANCE(v, texel) gibake_section_irradiance(v, texel)
#define GIBAKE_DDGI_SLOT(v, probe) gibake_slot_words[probe]
#endif  // GIBAKE_DDGI_SECTION_BUFFERS

#if !defined(GIBAKE_DDGI_SH) || !defined(GIBAKE_DDGI_STATE) || !defined(GIBAKE_DDGI_OFFSET) || \
    !defined(GIBAKE_DDGI_DEPTH)
#error "gibake/ddgi_sample.glsl: define GIBAKE_DDGI_SH, _STATE, _OFFSET and _DEPTH, or GIBAKE_DDGI_SECTION_BUFFERS"
#endif

#define GIBAKE_PROBE_SLOT_NONE 0xFFFFFFFFu

// Where probe `index` (x + X*(y + Y*z)) is stored: itself in a dense volume, its slot in a sparse
// one (GIBAKE_PROBE_SLOT_NONE when not stored, or without a GIBAKE_DDGI_SLOT accessor).
uint gibake_ddgi_slot(GibakeDdgiVolume v, uint index) {
  if (!gibake_ddgi_sparse(v)) return index;
#ifdef GIBAKE_DDGI_SLOT
  return GIBAKE_DDGI_SLOT(v, index);
#else
  return GIBAKE_PROBE_SLOT_NONE;
#endif
}

// The probe's tile in its atlases (column, row; the CPU's DdgiVolume::tile_cell): from its grid
// coordinate and the planes per row, or in a sparse volume from its slot.
uvec2 gibake_ddgi_tile_cell(GibakeDdgiVolume v, ivec3 coord, uint slot) {
  if (gibake_ddgi_sparse(v)) return uvec2(slot % v.atlas.z, slot / v.atlas.z);
  const uint k = v.atlas.z != 0u ? v.atlas.z : uint(v.counts.y);
  return uvec2(uint(coord.x) + uint(v.counts.x) * (uint(coord.y) % k), uint(coord.z) + uint(v.counts.z) * (uint(coord.y) / k));
}

// The CPU's helpers with its NaN behaviour (GLSL's clamp/max leave NaN undefined).
float gibake_saturate(float x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }
float gibake_max(float a, float b) { return a < b ? b : a; }  // std::max(a, b)
float gibake_clamp(float x, float lo, float hi) { return x < lo ? lo : (hi < x ? hi : x); }  // std::clamp

float gibake_dot(vec3 a, vec3 b) {
  precise float d = a.x * b.x + a.y * b.y + a.z * b.z;
  return d;
}

float gibake_length(vec3 a) {
  precise float l = sqrt(gibake_dot(a, a));
  return l;
}

// Division by the length, not GLSL's normalize (often a reciprocal square root): the CPU's bits.
vec3 gibake_normalize(vec3 a) {
  const float l = gibake_length(a);
  if (!(l > 0.0) || isinf(l)) return vec3(0.0, 0.0, 1.0);
  precise vec3 r = vec3(a.x / l, a.y / l, a.z / l);
  return r;
}

// Octahedral encoding into [-1,1]^2, z the hemisphere axis (gibake::loader::encode_oct).
vec2 gibake_encode_oct(vec3 d) {
  precise float l1 = abs(d.x) + abs(d.y) + abs(d.z);
  if (!(l1 > 0.0)) return vec2(0.0);
  precise float u = d.x / l1, w = d.y / l1;
  if (d.z < 0.0) {
    const float su = u >= 0.0 ? 1.0 : -1.0, sw = w >= 0.0 ? 1.0 : -1.0;
    precise float nu = (1.0 - abs(w)) * su, nw = (1.0 - abs(u)) * sw;
    u = nu;
    w = nw;
  }
  return vec2(u, w);
}

// E(N) from `coefficients` (4 or 9) RGB SH of radiance, the DESIGN.md basis and band factors,
// clamped >= 0 (gibake::loader::sh_irradiance). sh[c * 3 + channel].
vec3 gibake_sh_irradiance(float sh[27], uint coefficients, vec3 n) {
  const float x = n.x, y = n.y, z = n.z;
  // Band factor x basis constant as the CPU's float arithmetic rounds them (a0 = pi, a1 = 2 pi / 3,
  // a2 = pi / 4 times 0.282095, 0.488603, 1.092548, 0.315392, 0.546274); written as bits because
  // GLSL compilers fold constant expressions in double precision.
  const float c0 = uintBitsToFloat(0x3F62DFCFu), c1 = uintBitsToFloat(0x3F82FC67u);
  const float c2 = uintBitsToFloat(0x3F5BAB79u), c20 = uintBitsToFloat(0x3E7DA73Eu);
  const float c22 = uintBitsToFloat(0x3EDBAB79u);
  precise float basis[9] = float[9](c0, c1 * y, c1 * z, c1 * x, c2 * x * y, c2 * y * z, c20 * (3.0 * z * z - 1.0),
                                    c2 * x * z, c22 * (x * x - y * y));
  precise vec3 e = vec3(0.0);
  const uint count = min(coefficients, 9u);
  for (uint c = 0u; c < count; ++c)
    for (uint k = 0u; k < 3u; ++k) e[k] += basis[c] * sh[c * 3u + k];
  return vec3(e.x > 0.0 ? e.x : 0.0, e.y > 0.0 ? e.y : 0.0, e.z > 0.0 ? e.z : 0.0);  // NaN -> 0
}

// The 4 texels of bilinear filtering of the bordered tile at `cell` (gibake_ddgi_tile_cell) of
// `interior` texels a side in direction `dir`, clamped to the tile, and their weights, in the CPU's
// order (its sample_tile).
void gibake_tile_texels(GibakeDdgiVolume v, uvec2 cell, uint interior, vec3 dir, out ivec2 texels[4],
                        out float weights[4]) {
  const uint border = v.atlas.y, side = interior + 2u * border;
  const float tile = float(interior);
  const float ox = float(cell.x * side);
  const float oy = float(cell.y * side);
  const vec2 oct = gibake_encode_oct(dir);
  // Continuous texel coordinates (texel centres at +0.5) inside the tile interior.
  precise float fx = ox + float(border) + (oct.x * 0.5 + 0.5) * tile - 0.5;
  precise float fy = oy + float(border) + (oct.y * 0.5 + 0.5) * tile - 0.5;
  const float x0f = floor(fx), y0f = floor(fy);
  precise float tx = fx - x0f, ty = fy - y0f;
  const float hi_x = ox + float(side - 1u), hi_y = oy + float(side - 1u);
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const int x = int(gibake_clamp(x0f + float(i), ox, hi_x));
      const int y = int(gibake_clamp(y0f + float(j), oy, hi_y));
      precise float w = (i != 0 ? tx : 1.0 - tx) * (j != 0 ? ty : 1.0 - ty);
      texels[2 * j + i] = ivec2(x, y);
      weights[2 * j + i] = w;
    }
  }
}

// Depth moments (mean, mean^2) of the probe whose tile is at `cell` in direction `dir`, bilinear
// inside its bordered tile (the CPU's sample_depth).
vec2 gibake_sample_depth(GibakeDdgiVolume v, uvec2 cell, vec3 dir) {
  ivec2 texels[4];
  float weights[4];
  gibake_tile_texels(v, cell, v.atlas.x, dir, texels, weights);
  precise vec2 m = vec2(0.0);
  for (int t = 0; t < 4; ++t) {
    const vec2 d = GIBAKE_DDGI_DEPTH(v, texels[t]);
    m.x += weights[t] * d.x;
    m.y += weights[t] * d.y;
  }
  return m;
}

#ifdef GIBAKE_DDGI_IRRADIANCE
// Irradiance (lux) of the probe whose tile is at `cell` for surface normal n, bilinear inside its
// bordered irradiance atlas tile (the CPU's DdgiVolume::atlas_irradiance).
vec3 gibake_sample_irradiance_tile(GibakeDdgiVolume v, uvec2 cell, vec3 n) {
  ivec2 texels[4];
  float weights[4];
  gibake_tile_texels(v, cell, gibake_ddgi_irradiance_tile(v), n, texels, weights);
  precise vec3 e = vec3(0.0);
  for (int t = 0; t < 4; ++t) {
    precise vec3 rgb = GIBAKE_DDGI_IRRADIANCE(v, texels[t]);
    if (v.spacing.w > 0.0) rgb *= v.spacing.w;  // the CPU's irradiance_texel scales each texel
    e.x += weights[t] * rgb.x;
    e.y += weights[t] * rgb.y;
    e.z += weights[t] * rgb.z;
  }
  return e;
}
#endif

// Chebyshev visibility of a point `distance` from the probe (the CPU's chebyshev(): |mean^2 - mean2|
// and the cube as the bake's multi-bounce weights).
float gibake_chebyshev(vec2 m, float distance, float variance_floor) {
  if (!(distance > m.x)) return 1.0;  // in front of the mean occluder (also NaN-safe)
  precise float variance = gibake_max(abs(m.x * m.x - m.y), variance_floor);
  precise float delta = distance - m.x;
  precise float c = variance / (variance + delta * delta);
  precise float c3 = c * c * c;
  return c3;
}

// Base probe and trilinear fraction along each axis, the point clamped into the grid.
void gibake_ddgi_cell(GibakeDdgiVolume v, vec3 p, out ivec3 base, out vec3 alpha) {
  base = ivec3(0);
  alpha = vec3(0.0);
  for (int a = 0; a < 3; ++a) {
    const int last = v.counts[a] - 1;
    if (last == 0 || !(v.spacing[a] > 0.0)) continue;
    precise float g = (p[a] - v.grid_min[a]) / v.spacing[a];
    const float gc = gibake_clamp(isnan(g) || isinf(g) ? 0.0 : g, 0.0, float(last));
    base[a] = min(int(floor(gc)), last);
    precise float f = gc - float(base[a]);
    alpha[a] = gibake_saturate(f);
  }
}

// max(normal_bias, normal_bias_cells x the smallest spacing of an axis with more than one probe).
float gibake_ddgi_bias(GibakeDdgiVolume v, GibakeSampleOptions o) {
  float min_spacing = 0.0;
  for (int a = 0; a < 3; ++a)
    if (v.counts[a] > 1 && v.spacing[a] > 0.0)
      min_spacing = min_spacing > 0.0 ? min(min_spacing, v.spacing[a]) : v.spacing[a];
  precise float cells = o.normal_bias_cells * min_spacing;
  return gibake_max(o.normal_bias, cells);
}

// Back-face x visibility weight of one probe at `probe_pos` (before the floor and trilinear factor).
float gibake_probe_weight(GibakeDdgiVolume v, uvec2 cell, vec3 probe_pos, vec3 p, vec3 n, float bias,
                          GibakeSampleOptions o, bool visibility) {
  precise vec3 biased = vec3(p.x + n.x * bias, p.y + n.y * bias, p.z + n.z * bias);
  precise vec3 probe_to_point = biased - probe_pos;
  const vec3 dir = gibake_normalize(-probe_to_point);
  precise vec3 to_probe = probe_pos - p;
  const vec3 true_dir = gibake_normalize(to_probe);
  const float hard = gibake_saturate(gibake_dot(dir, n));
  const float facing = gibake_dot(true_dir, n);  // < 0: the probe lies behind the tangent plane
  precise float wrap_in = (facing + 1.0) * 0.5;
  const float wrap = gibake_max(0.0001, wrap_in);
  precise float weight = hard + (wrap * wrap + 0.2 - hard) * o.smooth_backface;
  if (o.behind_fade > 0.0) {
    precise float fade = 1.0 + facing / o.behind_fade;
    weight *= gibake_saturate(fade);
  }
  if (visibility) {
    const vec3 to_point = gibake_normalize(probe_to_point);
    weight *= gibake_chebyshev(gibake_sample_depth(v, cell, to_point), gibake_length(probe_to_point),
                               o.variance_floor);
  }
  return weight;
}

// DDGI irradiance (lux, >= 0) at world point p with unit normal n: the 8 probes of the cell holding
// p (clamped to the grid), inactive ones skipped, back-face and Chebyshev weights floored at
// min_weight, times the trilinear weight; the probes' irradiance atlas texels at n summed with these
// weights and normalised (use_irradiance_atlas, the volume with an irradiance atlas and
// GIBAKE_DDGI_IRRADIANCE defined), else the SH summed with these weights, normalised, then E(n).
// The same, false (and e = 0) when no probe weighs in: the volume has no answer at p. `sight`: the
// largest back-face x visibility weight of the probes weighed, before the floor (0 when none).
bool gibake_ddgi_try_irradiance(GibakeDdgiVolume v, vec3 p, vec3 n, GibakeSampleOptions o, out vec3 e,
                                out float sight) {
  e = vec3(0.0);
  sight = 0.0;
  ivec3 base;
  vec3 alpha;
  gibake_ddgi_cell(v, p, base, alpha);
  const bool visibility = o.use_visibility && (v.atlas.w & 1u) != 0u;
#ifdef GIBAKE_DDGI_IRRADIANCE
  // The atlas's texels are irradiance already: weighted as they are. The SH are weighted, then
  // turned into irradiance once.
  const bool atlas = o.use_irradiance_atlas && gibake_ddgi_irradiance_tile(v) != 0u;
#else
  const bool atlas = false;  // no accessor: the SH
#endif
  const float bias = gibake_ddgi_bias(v, o);
  const uint coefficients = uint(v.counts.w);
  float sum[27];
  for (int k = 0; k < 27; ++k) sum[k] = 0.0;
  precise float sum_weight = 0.0;
  for (int i = 0; i < 8; ++i) {
    const ivec3 off = ivec3(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    const ivec3 c = min(base + off, v.counts.xyz - 1);
    const uint index = gibake_ddgi_slot(v, uint(c.x + v.counts.x * (c.y + v.counts.y * c.z)));
    if (index == GIBAKE_PROBE_SLOT_NONE || GIBAKE_DDGI_STATE(v, index) == GIBAKE_PROBE_INACTIVE) continue;
    precise vec3 rest = vec3(v.grid_min.x + float(c.x) * v.spacing.x, v.grid_min.y + float(c.y) * v.spacing.y,
                             v.grid_min.z + float(c.z) * v.spacing.z);
    precise vec3 probe_pos = rest + GIBAKE_DDGI_OFFSET(v, index);
    const uvec2 cell = gibake_ddgi_tile_cell(v, c, index);
    precise float weight = gibake_probe_weight(v, cell, probe_pos, p, n, bias, o, visibility);
    const float unfloored = weight;
    weight = gibake_max(weight, o.min_weight);
    precise float trilinear = (off.x != 0 ? alpha.x : 1.0 - alpha.x) * (off.y != 0 ? alpha.y : 1.0 - alpha.y) *
                              (off.z != 0 ? alpha.z : 1.0 - alpha.z);
    weight *= trilinear;
    if (!(weight > 0.0)) continue;
    sight = gibake_max(sight, unfloored);
    if (atlas) {
#ifdef GIBAKE_DDGI_IRRADIANCE
      const vec3 rgb = gibake_sample_irradiance_tile(v, cell, n);
      for (uint k = 0u; k < 3u; ++k) {
        precise float term = rgb[k] * weight;
        precise float acc = sum[k] + term;
        sum[k] = acc;
      }
#endif
    } else {
      for (uint s = 0u; s < coefficients; ++s) {
        const vec3 rgb = GIBAKE_DDGI_SH(v, index, s);
        for (uint k = 0u; k < 3u; ++k) {
          precise float term = rgb[k] * weight;
          precise float acc = sum[s * 3u + k] + term;
          sum[s * 3u + k] = acc;
        }
      }
    }
    sum_weight += weight;
  }
  if (!(sum_weight > 0.0)) return false;
  if (atlas) {
    for (uint k = 0u; k < 3u; ++k) {
      precise float q = sum[k] / sum_weight;
      e[k] = q > 0.0 ? q : 0.0;  // also maps NaN to 0
    }
    return true;
  }
  for (uint k = 0u; k < coefficients * 3u; ++k) {
    precise float q = sum[k] / sum_weight;
    sum[k] = q;
  }
  e = gibake_sh_irradiance(sum, coefficients, n);
  return true;
}

bool gibake_ddgi_try_irradiance(GibakeDdgiVolume v, vec3 p, vec3 n, GibakeSampleOptions o, out vec3 e) {
  float sight;
  return gibake_ddgi_try_irradiance(v, p, n, o, e, sight);
}

vec3 gibake_ddgi_irradiance(GibakeDdgiVolume v, vec3 p, vec3 n, GibakeSampleOptions o) {
  vec3 e;
  gibake_ddgi_try_irradiance(v, p, n, o, e);
  return e;
}

vec3 gibake_ddgi_irradiance(GibakeDdgiVolume v, vec3 p, vec3 n) {
  return gibake_ddgi_irradiance(v, p, n, gibake_default_sample_options());
}

// ---- Several volumes (docs/FORMAT.md "Several volumes"; loader: BakeFile::sample_ddgi) ----
// A volume's region is its probe box grown by one spacing; g is p in probe-grid units. An axis of
// one probe is unbounded (gibake_ddgi_axis returns false there).
bool gibake_ddgi_axis(GibakeDdgiVolume v, vec3 p, int a, out float g, out float last) {
  g = 0.0;
  last = 0.0;
  if (v.counts[a] <= 1 || !(v.spacing[a] > 0.0)) return false;
  precise float q = (p[a] - v.grid_min[a]) / v.spacing[a];
  g = q;
  last = float(v.counts[a] - 1);
  return true;
}

// 1 in the probe box and up to half a spacing beyond it (the volume's cells), then linearly to 0 at
// one spacing beyond the outermost probe layer; the product over the axes.
float gibake_ddgi_blend_weight(GibakeDdgiVolume v, vec3 p) {
  precise float w = 1.0;
  for (int a = 0; a < 3; ++a) {
    float g, last;
    if (!gibake_ddgi_axis(v, p, a, g, last)) continue;
    if (isnan(g) || isinf(g)) return 0.0;
    precise float to_face = last - g;
    const float m = to_face < g ? to_face : g;
    precise float t = 2.0 * (1.0 + m);
    w *= t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  }
  return w;
}

bool gibake_ddgi_region_contains(GibakeDdgiVolume v, vec3 p) {
  for (int a = 0; a < 3; ++a) {
    float g, last;
    if (!gibake_ddgi_axis(v, p, a, g, last)) continue;
    precise float hi = last + 1.0;
    if (!(g >= -1.0 && g <= hi)) return false;
  }
  return true;
}

float gibake_ddgi_region_distance(GibakeDdgiVolume v, vec3 p) {
  precise float sum = 0.0;
  for (int a = 0; a < 3; ++a) {
    float g, last;
    if (!gibake_ddgi_axis(v, p, a, g, last)) continue;
    if (isnan(g) || isinf(g)) return uintBitsToFloat(0x7F800000u);
    precise float hi = last + 1.0;
    precise float below = -1.0 - g;
    precise float above = g - hi;
    const float cells = g < -1.0 ? below : (g > hi ? above : 0.0);
    precise float metres = cells * v.spacing[a];
    precise float square = metres * metres;
    sum += square;
  }
  return sqrt(sum);
}

#ifdef GIBAKE_DDGI_VOLUME
// The k-th volume of a walk: of the whole priority order (first == 0xFFFFFFFF), or of the index's
// list whose first id is word `first` of the index.
GibakeDdgiVolume gibake_ddgi_walk_volume(uint first, uint k) {
#ifdef GIBAKE_DDGI_INDEX
  if (first != 0xFFFFFFFFu) return GIBAKE_DDGI_VOLUME_OF(GIBAKE_DDGI_INDEX(first + k));
#endif
  return GIBAKE_DDGI_VOLUME(k);
}

// The blend over `count` volumes in priority order (the loader's blend in sample_ddgi, its
// operations in its order); false when no region of them holds p.
bool gibake_ddgi_blend_walk(uint first, uint count, vec3 p, vec3 n, GibakeSampleOptions o, out vec3 result) {
  vec3 sum = vec3(0.0), lone = vec3(0.0), unseen_answer = vec3(0.0);
  float taken = 0.0;
  int contributors = 0;
  bool any_inside = false, any_unseen = false;
  GibakeDdgiVolume first_inside;
  result = vec3(0.0);
  for (uint i = 0u; i < count; ++i) {
    const GibakeDdgiVolume v = gibake_ddgi_walk_volume(first, i);
    if (!gibake_ddgi_region_contains(v, p)) continue;
    if (!any_inside) {
      first_inside = v;
      any_inside = true;
    }
    const float region = gibake_ddgi_blend_weight(v, p);
    if (!(region > 0.0)) continue;
    vec3 e;
    float sight;
    if (!gibake_ddgi_try_irradiance(v, p, n, o, e, sight)) continue;
    // A volume whose probes barely see p answers with the floor's weights: trust it that much less.
    precise float seen = region * (sight / GIBAKE_DDGI_FULL_SIGHT);
    const float w = sight >= GIBAKE_DDGI_FULL_SIGHT ? region : seen;
    if (!(w > 0.0)) {
      if (!any_unseen) {
        unseen_answer = e;
        any_unseen = true;
      }
      continue;
    }
    precise float left = 1.0 - taken;
    precise float c = w >= 1.0 ? left : w * left;
    for (int k = 0; k < 3; ++k) {
      precise float term = c * e[k];
      precise float acc = sum[k] + term;
      sum[k] = acc;
    }
    precise float t = taken + c;
    taken = w >= 1.0 ? 1.0 : t;
    lone = e;
    ++contributors;
    if (taken >= 1.0) break;
  }
  if (!any_inside) return false;
  if (contributors == 0) {
    result = any_unseen ? unseen_answer : gibake_ddgi_irradiance(first_inside, p, n, o);
  } else if (contributors == 1) {
    result = lone;
  } else {
    for (int k = 0; k < 3; ++k) {
      precise float q = taken < 1.0 ? sum[k] / taken : sum[k];
      result[k] = q;
    }
  }
  return true;
}

// Irradiance (lux) at p blended over `count` volumes: define GIBAKE_DDGI_VOLUME(i) → GibakeDdgiVolume,
// the i-th volume in priority order (finest spacing first, ties in file order: the loader's
// BakeFile::ddgi_priority()), and accessors that read each volume's own data (pick it by v.engine).
// Each volume with weight w > 0 at p (its region weight times min(1, sight / GIBAKE_DDGI_FULL_SIGHT))
// and an answer there takes w x (1 - what the finer ones took), until all is taken; a sum that ends short of 1 is divided by what was taken; a lone contributor
// answers as it is. `inside` false: p lies outside every region, and the result is the clamped
// answer of the nearest volume. It loops over every volume: with many, use the indexed variant below.
vec3 gibake_ddgi_blended_irradiance(uint count, vec3 p, vec3 n, GibakeSampleOptions o, out bool inside) {
  vec3 result;
  inside = gibake_ddgi_blend_walk(0xFFFFFFFFu, count, p, n, o, result);
  if (inside) return result;
  int nearest = -1;
  float best = 0.0;
  for (uint i = 0u; i < count; ++i) {
    const float d = gibake_ddgi_region_distance(GIBAKE_DDGI_VOLUME(i), p);
    if (nearest < 0 || d < best) {
      nearest = int(i);
      best = d;
    }
  }
  return nearest < 0 ? vec3(0.0) : gibake_ddgi_irradiance(GIBAKE_DDGI_VOLUME(uint(nearest)), p, n, o);
}

vec3 gibake_ddgi_blended_irradiance(uint count, vec3 p, vec3 n) {
  bool inside;
  return gibake_ddgi_blended_irradiance(count, p, n, gibake_default_sample_options(), inside);
}

#ifdef GIBAKE_DDGI_INDEX
// The same blend through the file's ddgi_volume_index (format 1.4, docs/FORMAT.md "Volume index"):
// only the volumes p's cell lists, in the same order, so the same value as
// gibake_ddgi_blended_irradiance at a cost that does not grow with the volume count. Define also
// GIBAKE_DDGI_INDEX(i) → uint, word i of the section's payload as the file stores it, and
// GIBAKE_DDGI_VOLUME_OF(id) → GibakeDdgiVolume, the volume of file index id (the id-th ddgi_volume
// section; e.g. GIBAKE_DDGI_VOLUME(rank[id]) with rank the inverse of ddgi_priority()). Outside the
// index grid, in an empty cell or where no listed region holds p, it loops over all `count`.
vec3 gibake_ddgi_indexed_irradiance(uint count, vec3 p, vec3 n, GibakeSampleOptions o, out bool inside) {
  const float cell_size = uintBitsToFloat(GIBAKE_DDGI_INDEX(3u));
  const uint cells = GIBAKE_DDGI_INDEX(7u);
  bool in_grid = true;
  uint at[3];
  for (int a = 0; a < 3; ++a) {
    const uint dims = GIBAKE_DDGI_INDEX(4u + uint(a));
    precise float x = (p[a] - uintBitsToFloat(GIBAKE_DDGI_INDEX(uint(a)))) / cell_size;
    if (!(x >= 0.0 && x < float(dims))) {
      in_grid = false;
      at[a] = 0u;
    } else {
      at[a] = min(uint(x), dims - 1u);
    }
  }
  if (in_grid) {
    const uint cell = at[0] + GIBAKE_DDGI_INDEX(4u) * (at[1] + GIBAKE_DDGI_INDEX(5u) * at[2]);
    const uint begin = GIBAKE_DDGI_INDEX(16u + cell), end = GIBAKE_DDGI_INDEX(17u + cell);
    vec3 result;
    if (end > begin && gibake_ddgi_blend_walk(17u + cells + begin, end - begin, p, n, o, result)) {
      inside = true;
      return result;
    }
  }
  return gibake_ddgi_blended_irradiance(count, p, n, o, inside);
}

vec3 gibake_ddgi_indexed_irradiance(uint count, vec3 p, vec3 n) {
  bool inside;
  return gibake_ddgi_indexed_irradiance(count, p, n, gibake_default_sample_options(), inside);
}
#endif  // GIBAKE_DDGI_INDEX
#endif  // GIBAKE_DDGI_VOLUME

#endif  // GIBAKE_DDGI_SAMPLE_GLSL
