// An engine's fragment shader lighting a surface from a gibake voxel-GI bake with the installed
// cone tracer (gibake/vxgi_cone.glsl): diffuse irradiance from the six 60-degree cones plus a
// specular cone, the voxel radiance in the engine's own 3D textures (one per clipmap face, levels
// as mips) and the SDF as an R32F 3D texture. Built against the installed package (CMakeLists.txt)
// when glslc is found, so the shipped include is known to compile.
#version 450
#extension GL_GOOGLE_include_directive : require

const uint kClipmaps = 2u;
// What the engine keeps of each clipmap's gibake_vxgi_volume (loader::VxgiVolume::desc()).
struct ClipmapDesc {
  vec4 grid_min_size;  // grid_min, voxel_size
  uvec4 dims_levels;   // dims, levels
  vec4 sky_scale;      // sky, diffuse_scale
};
layout(set = 2, binding = 0) uniform sampler3D vxgi_faces[kClipmaps * 6u];  // [clipmap * 6 + face], mips = levels
layout(set = 2, binding = 1) uniform sampler3D vxgi_sdf[kClipmaps];
layout(set = 2, binding = 2) uniform Clipmaps { ClipmapDesc desc[kClipmaps]; } clipmaps;

#define GIBAKE_VXGI_SDF
#include "gibake/vxgi_cone.glsl"

uint gibake_vxgi_clipmap_count() { return kClipmaps; }

GibakeVxgiVolume gibake_vxgi_clipmap(uint k) {
  ClipmapDesc d = clipmaps.desc[k];
  return GibakeVxgiVolume(d.grid_min_size.xyz, d.grid_min_size.w, ivec3(d.dims_levels.xyz), d.dims_levels.w,
                          d.sky_scale.xyz, d.sky_scale.w, k, true, 6u);
}

vec4 gibake_vxgi_fetch(uint clipmap, uint level, uint face, ivec3 c) {
  return texelFetch(vxgi_faces[clipmap * 6u + face], c, int(level));
}

float gibake_vxgi_fetch_sdf(uint clipmap, ivec3 c) { return texelFetch(vxgi_sdf[clipmap], c, 0).r; }

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 albedo;
layout(location = 3) in vec3 to_eye;
layout(location = 0) out vec4 colour;

void main() {
  GibakeConeOptions o = gibake_default_cone_options();
  vec3 irradiance = gibake_vxgi_cone_trace_diffuse(world_position, world_normal, o);
  vec4 specular = gibake_vxgi_cone_trace_specular(world_position, world_normal, to_eye, 0.4, o);
  colour = vec4(albedo * irradiance / 3.14159265 + 0.04 * specular.rgb, 1.0);
}
