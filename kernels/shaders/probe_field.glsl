// A bake's DDGI volumes as a kernel reads them through the GLSL sampler (gibake/ddgi_sample.glsl):
// every volume's decoded data in four buffers, packed by bake/vulkan/probe_field.cpp
// (pack_probe_field, which documents the layout), and probe_field_irradiance(p, n), the loader's
// BakeFile::sample_ddgi with its default options: the volumes blended, through the file's volume
// index when it has one. Define PROBE_FIELD_BINDING (the first of the four bindings, set 0) before
// including this.
#ifndef GIBAKE_PROBE_FIELD_GLSL
#define GIBAKE_PROBE_FIELD_GLSL

// Words 0..3: volume count, the index's first word (0xFFFFFFFF: no index), the priority ranks' first
// word, 0; then each probe's state, then the index payload as stored, then each file volume's rank.
layout(std430, set = 0, binding = PROBE_FIELD_BINDING) readonly buffer ProbeFieldWords { uint pf_words[]; };
// Each probe's relocation offset (xyz), then every irradiance atlas texel (RGBA, lux).
layout(std430, set = 0, binding = PROBE_FIELD_BINDING + 1) readonly buffer ProbeFieldVec4 { vec4 pf_vec4[]; };
// Every SH coefficient's RGB (padded to an even count), then every depth atlas texel (mean, mean^2).
layout(std430, set = 0, binding = PROBE_FIELD_BINDING + 2) readonly buffer ProbeFieldFloats { float pf_floats[]; };
struct ProbeFieldVolumeWords {  // GibakeDdgiVolume's layout, declared before the include defines it
  vec4 grid_min, spacing;
  ivec4 counts;
  uvec4 atlas, formats, engine;
};
// Each volume in priority order; its engine words say where its data starts: x its first irradiance
// texel in pf_vec4, y its first probe, z its first depth texel (pairs of pf_floats), w its first
// SH triplet.
layout(std430, set = 0, binding = PROBE_FIELD_BINDING + 3) readonly buffer ProbeFieldVolumes {
  ProbeFieldVolumeWords pf_volumes[];
};

const uint kProbeFieldHeaderWords = 4u;

#define GIBAKE_DDGI_SH_AT(v, probe, c) (((v).engine.w + (probe) * uint((v).counts.w) + (c)) * 3u)
#define GIBAKE_DDGI_SH(v, probe, c)                                                            \
  vec3(pf_floats[GIBAKE_DDGI_SH_AT(v, probe, c)], pf_floats[GIBAKE_DDGI_SH_AT(v, probe, c) + 1u], \
       pf_floats[GIBAKE_DDGI_SH_AT(v, probe, c) + 2u])
#define GIBAKE_DDGI_STATE(v, probe) pf_words[kProbeFieldHeaderWords + (v).engine.y + (probe)]
#define GIBAKE_DDGI_OFFSET(v, probe) pf_vec4[(v).engine.y + (probe)].xyz
#define GIBAKE_DDGI_ATLAS_AT(v, first, interior, texel) \
  ((first) + uint((texel).y) * gibake_ddgi_atlas_width(v, interior) + uint((texel).x))
#define GIBAKE_DDGI_DEPTH_AT(v, texel) (2u * GIBAKE_DDGI_ATLAS_AT(v, (v).engine.z, (v).atlas.x, texel))
#define GIBAKE_DDGI_DEPTH(v, texel) \
  vec2(pf_floats[GIBAKE_DDGI_DEPTH_AT(v, texel)], pf_floats[GIBAKE_DDGI_DEPTH_AT(v, texel) + 1u])
#define GIBAKE_DDGI_IRRADIANCE(v, texel) \
  pf_vec4[GIBAKE_DDGI_ATLAS_AT(v, (v).engine.x, gibake_ddgi_irradiance_tile(v), texel)].rgb
#define GIBAKE_DDGI_VOLUME(i)                                                                          \
  GibakeDdgiVolume(pf_volumes[i].grid_min, pf_volumes[i].spacing, pf_volumes[i].counts, pf_volumes[i].atlas, \
                   pf_volumes[i].formats, pf_volumes[i].engine)
#define GIBAKE_DDGI_INDEX(i) pf_words[pf_words[1] + (i)]
#define GIBAKE_DDGI_VOLUME_OF(id) GIBAKE_DDGI_VOLUME(pf_words[pf_words[2] + (id)])
#include "gibake/ddgi_sample.glsl"

// Irradiance (lux) at p about unit normal n from every volume of the field, as BakeFile::sample_ddgi
// answers with default options.
vec3 probe_field_irradiance(vec3 p, vec3 n) {
  bool inside;
  const GibakeSampleOptions o = gibake_default_sample_options();
  if (pf_words[1] == 0xFFFFFFFFu) return gibake_ddgi_blended_irradiance(pf_words[0], p, n, o, inside);
  return gibake_ddgi_indexed_irradiance(pf_words[0], p, n, o, inside);
}

#endif  // GIBAKE_PROBE_FIELD_GLSL
