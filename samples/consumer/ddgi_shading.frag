// An engine's fragment shader lighting a diffuse surface with gibake's GLSL sampler, over every DDGI
// volume of a bake: a default bake holds the default grid and refined volumes where the light
// changes, and sampling only the first would miss them. The probe data lives in the engine's own
// buffers, each volume's after the one before (as main.cpp's shader_buffers() lays them out), read
// through the accessors the include asks for; each volume's GibakeDdgiVolume carries in its
// `engine` words where its data starts. Defining the optional irradiance accessor makes the sampler
// read each probe's irradiance from its irradiance atlas tile, as the loader's CPU sampler does by
// default, instead of from its SH. A sparse volume (format 1.5: a near-surface volume stores only
// the probes a sampler reads) is read through its slot map, GIBAKE_DDGI_SLOT. Built against the installed package (CMakeLists.txt) when
// glslc is found, so the shipped include is known to compile.
#version 450
#extension GL_GOOGLE_include_directive : require

// Per stored probe (a sparse volume's in slot order): 9 SH coefficients' RGB (L1 volumes leave 5
// zero, so that one index finds a probe's SH, state and offset), its state, its offset.
layout(set = 1, binding = 0) readonly buffer ProbeSh { float probe_sh[]; };  // [probe][9][rgb]
layout(set = 1, binding = 1) readonly buffer ProbeStates { uint probe_states[]; };
layout(set = 1, binding = 2) readonly buffer ProbeOffsets { vec4 probe_offsets[]; };
layout(set = 1, binding = 3) readonly buffer ProbeDepth { vec2 probe_depth[]; };  // each atlas, row after row
layout(set = 1, binding = 7) readonly buffer ProbeIrradiance { vec4 probe_irradiance[]; };  // likewise, RGBA (lux)
// Each sparse volume's ddgi_probe_slots payload as stored (one zero word when no volume is sparse).
layout(set = 1, binding = 8) readonly buffer ProbeSlots { uint probe_slots[]; };

// GibakeDdgiVolume's layout, declared before the include defines the struct: each volume's
// loader::DdgiVolume::glsl_volume() in BakeFile::ddgi_priority() order, with engine = (its first
// irradiance atlas texel, its first stored probe, its first depth texel, its first word in
// probe_slots); the atlases' widths follow from the volume (gibake_ddgi_atlas_width).
struct VolumeWords {
  vec4 grid_min, spacing;
  ivec4 counts;
  uvec4 atlas, formats, engine;
};
layout(set = 1, binding = 4) readonly buffer Volumes { VolumeWords volumes[]; };
// The file's ddgi_volume_index payload as stored (one zero word when the file has none), and each
// file volume's rank in the priority order.
layout(set = 1, binding = 5) readonly buffer VolumeIndex { uint index_words[]; };
layout(set = 1, binding = 6) readonly buffer VolumeRanks { uint volume_ranks[]; };
layout(push_constant) uniform Lighting {
  uint volume_count;
  uint has_index;  // 0: blend over every volume (a file of one volume has no index)
};

#define GIBAKE_DDGI_SH_AT(v, probe, c) ((((v).engine.y + (probe)) * 9u + (c)) * 3u)
#define GIBAKE_DDGI_SH(v, probe, c)                                                    \
  vec3(probe_sh[GIBAKE_DDGI_SH_AT(v, probe, c)], probe_sh[GIBAKE_DDGI_SH_AT(v, probe, c) + 1u], \
       probe_sh[GIBAKE_DDGI_SH_AT(v, probe, c) + 2u])
#define GIBAKE_DDGI_STATE(v, probe) probe_states[(v).engine.y + (probe)]
#define GIBAKE_DDGI_OFFSET(v, probe) probe_offsets[(v).engine.y + (probe)].xyz
#define GIBAKE_DDGI_SLOT(v, probe) probe_slots[(v).engine.w + (probe)]
// Texel `texel` of an atlas starting at element `first`; the include defines gibake_ddgi_atlas_width
// before it expands the accessors.
#define GIBAKE_DDGI_ATLAS_AT(v, first, interior, texel) \
  ((first) + uint((texel).y) * gibake_ddgi_atlas_width(v, interior) + uint((texel).x))
#define GIBAKE_DDGI_DEPTH(v, texel) probe_depth[GIBAKE_DDGI_ATLAS_AT(v, (v).engine.z, (v).atlas.x, texel)]
#define GIBAKE_DDGI_IRRADIANCE(v, texel) \
  probe_irradiance[GIBAKE_DDGI_ATLAS_AT(v, (v).engine.x, gibake_ddgi_irradiance_tile(v), texel)].rgb
#define GIBAKE_DDGI_VOLUME(i)                                                                        \
  GibakeDdgiVolume(volumes[i].grid_min, volumes[i].spacing, volumes[i].counts, volumes[i].atlas,      \
                   volumes[i].formats, volumes[i].engine)
#define GIBAKE_DDGI_INDEX(i) index_words[i]
#define GIBAKE_DDGI_VOLUME_OF(id) GIBAKE_DDGI_VOLUME(volume_ranks[id])
#include "gibake/ddgi_sample.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 albedo;
layout(location = 0) out vec4 colour;

void main() {
  const vec3 n = normalize(world_normal);
  bool inside;
  const GibakeSampleOptions o = gibake_default_sample_options();
  // Pass the surface point itself: the sampler adds the normal bias.
  const vec3 irradiance = has_index != 0u ? gibake_ddgi_indexed_irradiance(volume_count, world_position, n, o, inside)
                                          : gibake_ddgi_blended_irradiance(volume_count, world_position, n, o, inside);
  colour = vec4(albedo / 3.14159265 * irradiance, 1.0);  // lux to diffuse radiance, cd/m^2
}
