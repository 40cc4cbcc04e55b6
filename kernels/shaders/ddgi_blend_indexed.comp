// The indexed GLSL blend of several DDGI volumes (gibake_ddgi_indexed_irradiance): as
// ddgi_blend_accessors.comp, plus the file's ddgi_volume_index payload (binding 9, as stored) and
// each file volume's priority rank (binding 10), so GIBAKE_DDGI_VOLUME_OF(id) is
// GIBAKE_DDGI_VOLUME(rank[id]). tests/vulkan/ddgi_blend_glsl_test.cpp compares it with the loader's
// BakeFile::sample_ddgi.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Sh { float sh[]; };  // [probe][9][rgb]
// Every stored probe's state, then every volume's slot map (a sparse volume's, format 1.5).
layout(std430, set = 0, binding = 1) readonly buffer States { uint states[]; };
layout(std430, set = 0, binding = 2) readonly buffer Offsets { vec4 offsets[]; };
layout(std430, set = 0, binding = 3) readonly buffer Depth { vec2 depth[]; };
layout(std430, set = 0, binding = 4) readonly buffer Irradiance { vec4 irradiance_atlas[]; };  // RGB, alpha

struct GibakeDdgiVolumeWords {  // GibakeDdgiVolume's layout, declared before the include defines it
  vec4 grid_min, spacing;
  ivec4 counts;
  uvec4 atlas, formats, engine;
};
layout(std430, set = 0, binding = 5) readonly buffer Volumes { GibakeDdgiVolumeWords volumes[]; };

#define GIBAKE_DDGI_SH_AT(v, probe, c) ((((v).engine.y + (probe)) * 9u + (c)) * 3u)
#define GIBAKE_DDGI_SH(v, probe, c) \
  vec3(sh[GIBAKE_DDGI_SH_AT(v, probe, c)], sh[GIBAKE_DDGI_SH_AT(v, probe, c) + 1u], sh[GIBAKE_DDGI_SH_AT(v, probe, c) + 2u])
#define GIBAKE_DDGI_STATE(v, probe) states[(v).engine.y + (probe)]
#define GIBAKE_DDGI_OFFSET(v, probe) offsets[(v).engine.y + (probe)].xyz
#define GIBAKE_DDGI_SLOT(v, probe) states[(v).engine.w + (probe)]
// Texel `texel` of an atlas starting at element `first`, its width from the volume
// (gibake_ddgi_atlas_width, which the include defines before it expands the accessors).
#define GIBAKE_DDGI_ATLAS_AT(v, first, interior, texel) \
  ((first) + uint((texel).y) * gibake_ddgi_atlas_width(v, interior) + uint((texel).x))
#define GIBAKE_DDGI_DEPTH(v, texel) depth[GIBAKE_DDGI_ATLAS_AT(v, (v).engine.z, (v).atlas.x, texel)]
#define GIBAKE_DDGI_IRRADIANCE(v, texel) \
  irradiance_atlas[GIBAKE_DDGI_ATLAS_AT(v, (v).engine.x, gibake_ddgi_irradiance_tile(v), texel)].rgb
// Expanded where the sampler uses it, after the include has declared GibakeDdgiVolume.
#define GIBAKE_DDGI_VOLUME(i)                                                                          \
  GibakeDdgiVolume(volumes[i].grid_min, volumes[i].spacing, volumes[i].counts, volumes[i].atlas,        \
                   volumes[i].formats, volumes[i].engine)
layout(std430, set = 0, binding = 9) readonly buffer Index { uint index_words[]; };
layout(std430, set = 0, binding = 10) readonly buffer Ranks { uint ranks[]; };
#define GIBAKE_DDGI_INDEX(i) index_words[i]
#define GIBAKE_DDGI_VOLUME_OF(id) GIBAKE_DDGI_VOLUME(ranks[id])
#include "gibake/ddgi_sample.glsl"

layout(std430, set = 0, binding = 6) readonly buffer Params {
  GibakeSampleOptions options;
  uint volume_count;
  uint query_count;
};
layout(std430, set = 0, binding = 7) readonly buffer Queries { vec4 queries[]; };  // P, N per query
layout(std430, set = 0, binding = 8) writeonly buffer Result { vec4 irradiance[]; };  // rgb, 1 inside

void main() {
  const uint q = gl_GlobalInvocationID.x;
  if (q >= query_count) return;
  bool inside;
  const vec3 e = gibake_ddgi_indexed_irradiance(volume_count, queries[2u * q].xyz, queries[2u * q + 1u].xyz,
                                               options, inside);
  irradiance[q] = vec4(e, inside ? 1.0 : 0.0);
}
