// Probe rays on the GPU, one per invocation: in mode 0 the path-traced gather, the twin of
// bake/trace/path_gather.cpp trace_probe_paths; in mode 1 the probe-feedback gather's hits
// (trace_probe_rays); in mode 2 the reconstruction check's reference paths (same random streams, same rules; see that file for why
// each rule is what it is). Hit shading follows bake/scene/material.cpp, lights kernels/shade.cpp,
// emitters bake/scene/emitters.cpp, the sky bake/scene/sky.cpp.
// Included by path.comp, and by path_probe_field.comp with PATH_PROBE_FIELD defined: there mode 2
// also records where each path would end at its first hit in a bake's probes (path_gather.cpp
// path_radiance's probe_lit), which probe_field_ended.comp then lights from them, for the surface
// fit's blend of both estimates.
#ifndef GIBAKE_PATH_KERNEL_GLSL
#define GIBAKE_PATH_KERNEL_GLSL

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Nodes { GpuBvhNode nodes[]; };
layout(std430, set = 0, binding = 1) readonly buffer Tris { GpuTriangle tris[]; };
layout(std430, set = 0, binding = 2) readonly buffer AlphaTris { GpuAlphaTriangle alpha_tris[]; };
layout(std430, set = 0, binding = 3) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, set = 0, binding = 4) readonly buffer Textures { GpuTexture textures[]; };
layout(std430, set = 0, binding = 5) readonly buffer Texels { uint texels[]; };
layout(std430, set = 0, binding = 6) readonly buffer Verts { GpuVertex verts[]; };
layout(std430, set = 0, binding = 7) readonly buffer ShadeTris { GpuShadeTri shade_tris[]; };
layout(std430, set = 0, binding = 8) readonly buffer ShadeMats { GpuShadeMaterial shade_mats[]; };
layout(std430, set = 0, binding = 9) readonly buffer ShadeTex { GpuShadeTexture shade_tex[]; };
layout(std430, set = 0, binding = 10) readonly buffer Levels { GpuTexLevel levels[]; };
layout(std430, set = 0, binding = 11) readonly buffer Pool { uint pool[]; };
layout(std430, set = 0, binding = 12) readonly buffer Srgb { float srgb[]; };
layout(std430, set = 0, binding = 13) readonly buffer Lights { GpuLight lights[]; };
layout(std430, set = 0, binding = 14) readonly buffer EmitCdf { float emit_cdf[]; };
layout(std430, set = 0, binding = 15) readonly buffer EmitTris { uint emit_tris[]; };
layout(std430, set = 0, binding = 16) readonly buffer SkyMap { float sky_rgb[]; };
layout(std430, set = 0, binding = 17) readonly buffer Params { GpuPathParams P; };
layout(std430, set = 0, binding = 18) readonly buffer Rays { GpuPathRay rays[]; };
// Mode 2: the points whose reference paths each invocation makes (push.samples.w paths a point).
layout(std430, set = 0, binding = 18) readonly buffer Points { GpuReferencePoint points[]; };
layout(std430, set = 0, binding = 19) writeonly buffer Out { GpuPathOut outs[]; };
// The integration's device buffer (bake/vulkan/integrate.h): each ray's sample, when push.samples.x.
layout(std430, set = 0, binding = 20) writeonly buffer Samples { GpuRaySample samples[]; };
// Instead of `outs` when push.samples.z: the part of each output the host reads.
layout(std430, set = 0, binding = 21) writeonly buffer Briefs { GpuPathBrief briefs[]; };
// With the probe's emitter samples (P.sky_map.w): each ray's paired sample (trace_probe_paths' `lights`).
layout(std430, set = 0, binding = 22) writeonly buffer LightOut { GpuRaySample light_out[]; };
// The sky map's sampling tables (Sky::row_cdf, then Sky::col_cdf), when the probe samples the map.
layout(std430, set = 0, binding = 23) readonly buffer SkyCdf { float sky_cdf[]; };
// Per lane position of a probe's rays, the ray it traces (raygen.comp made rays[i] that ray; bake/vulkan/raygen.h
// lane_order): every result goes to the ray's own position, so the outputs are in ray order.
layout(std430, set = 0, binding = 24) readonly buffer Order { uint order[]; };
layout(push_constant) uniform Push { PathPush push; };
#ifdef PATH_PROBE_FIELD
// Mode 2: where each path would have ended at its first hit, three vec4s a path (FirstHit below),
// for probe_field_ended.comp to light from the probes.
layout(std430, set = 0, binding = 25) writeonly buffer FirstHits { vec4 first_hits[]; };
#endif

#include "traverse.glsl"

const float kPi = 3.14159265358979323846;
const float kInf = 1.0 / 0.0;

// --- counter-based random numbers (kernels/ray_gen.cpp) ---
#include "rng.glsl"
// Streams of a path vertex (bake/trace/path_gather.cpp).
uint stream_of(int depth, uint s) { return 16u + 8u * uint(depth) + s; }

// --- textures (bake/scene/material.cpp, bake/scene/texture_lod.cpp) ---
vec4 sample_level(uint level, uint wrap, vec2 uv, bool decode_srgb) {
  uvec4 li = levels[level].info;
  int width = int(li.y), height = int(li.z);
  float x = uv.x * float(width) - 0.5, y = uv.y * float(height) - 0.5;
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int x0 = int(fx), y0 = int(fy);
  int xs[2] = int[2](wrap_coord(x0, width, wrap & 0xFFFFu), wrap_coord(x0 + 1, width, wrap & 0xFFFFu));
  int ys[2] = int[2](wrap_coord(y0, height, wrap >> 16), wrap_coord(y0 + 1, height, wrap >> 16));
  float wx[2] = float[2](1.0 - ax, ax), wy[2] = float[2](1.0 - ay, ay);
  vec4 o = vec4(0.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      uint px = pool[li.x + uint(ys[j] * width + xs[i])];
      float w = wx[i] * wy[j];
      for (int c = 0; c < 3; ++c) {
        uint b = (px >> (8 * c)) & 255u;
        o[c] += w * (decode_srgb ? srgb[b] : float(b) / 255.0);
      }
      o.w += w * (float(px >> 24) / 255.0);
    }
  return o;
}

vec2 transform_uv(vec2 uv, vec4 xform, float rotation, float has_transform) {
  if (has_transform == 0.0) return uv;
  float su = uv.x * xform.z, sv = uv.y * xform.w;
  float c = cos(rotation), s = sin(rotation);
  return vec2(c * su + s * sv + xform.x, -s * su + c * sv + xform.y);
}

// A material texture at uv with the ray-cone footprint (width 0: level 0); rgb sRGB-decoded or linear.
vec4 sample_texture(uint tex, uint tri, vec2 uv_in, vec4 xform, float rotation, float has_transform, float width,
                    float cos_theta, bool decode_srgb) {
  uvec4 ti = shade_tex[tex].info;
  if (ti.y == 0u) return vec4(1.0);
  vec2 uv = transform_uv(uv_in, xform, rotation, has_transform);
  uint level = 0u;
  if (width > 0.0 && ti.y > 1u) {
    uvec4 l0 = levels[ti.x].info;
    float su = has_transform != 0.0 ? xform.z : 1.0, sv = has_transform != 0.0 ? xform.w : 1.0;
    // The footprint capped at a share of the triangle's uv extent (TextureLod::level_of).
    float uv_width = min(width / max(abs(cos_theta), 0.1) * shade_tris[tri].extra.x,
                         shade_tris[tri].extra.w);
    float texels = uv_width * sqrt(float(l0.y) * float(l0.z) * abs(su * sv));
    float lod = (texels > 1.0 && !isinf(texels) && !isnan(texels)) ? log2(texels) : 0.0;
    level = uint(min(int(lod + 0.5), int(ti.y) - 1));
  }
  return sample_level(ti.x + level, ti.z, uv, decode_srgb);
}

struct Surface {
  vec3 albedo, emission, normal;
  float transmission;  // factor x transmission texture red (linear)
  bool double_sided;
};

Surface surface_sample(uint tri, float u, float v, float width, float cos_theta) {
  GpuShadeTri st = shade_tris[tri];
  GpuShadeMaterial m = shade_mats[st.idx_mat.w];
  GpuVertex a = verts[st.idx_mat.x], b = verts[st.idx_mat.y], c = verts[st.idx_mat.z];
  float w0 = 1.0 - u - v;
  Surface s;
  s.double_sided = m.tex.z != 0u;
  vec2 uv = vec2(w0 * a.pos_u.w + u * b.pos_u.w + v * c.pos_u.w, w0 * a.normal_v.w + u * b.normal_v.w + v * c.normal_v.w);
  vec4 vc = w0 * a.color + u * b.color + v * c.color;
  s.albedo = m.base_color.rgb * vc.rgb;
  if (m.tex.x != GPU_NO_TEXTURE)
    s.albedo *= sample_texture(m.tex.x, tri, uv, m.base_xform, m.rot.x, m.rot.y, width, cos_theta, true).rgb;
  s.transmission = uintBitsToFloat(m.tex.w);
  if (m.trans_tex.x != GPU_NO_TEXTURE)
    s.transmission *= sample_texture(m.trans_tex.x, tri, uv, m.trans_xform, uintBitsToFloat(m.trans_tex.y),
                                     float(m.trans_tex.z), width, cos_theta, false).r;
  s.emission = vec3(0.0);
  if (m.emissive.w > 0.0) {
    vec3 e = m.emissive.rgb;
    if (m.tex.y != GPU_NO_TEXTURE)
      e *= sample_texture(m.tex.y, tri, uv, m.emit_xform, m.rot.z, m.rot.w, width, cos_theta, true).rgb;
    s.emission = e * m.emissive.w;
  }
  vec3 n = w0 * a.normal_v.xyz + u * b.normal_v.xyz + v * c.normal_v.xyz;
  s.normal = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0);
  return s;
}

// --- sky (bake/scene/sky.cpp) ---
vec3 sky_radiance(vec3 d) {
  int width = int(P.sky_map.x), height = int(P.sky_map.y);
  if (width <= 0 || height <= 0) return P.sky.rgb * P.sky.w;
  float u = 0.5 + atan(d.x, -d.z) / (2.0 * kPi);
  float v = acos(clamp(d.y, -1.0, 1.0)) / kPi;
  float x = u * float(width) - 0.5, y = v * float(height) - 0.5;
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int x0 = int(fx), y0 = int(fy);
  int xs[2] = int[2](((x0 % width) + width) % width, (((x0 + 1) % width) + width) % width);
  int ys[2] = int[2](clamp(y0, 0, height - 1), clamp(y0 + 1, 0, height - 1));
  float wx[2] = float[2](1.0 - ax, ax), wy[2] = float[2](1.0 - ay, ay);
  vec3 o = vec3(0.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      uint k = uint(ys[j] * width + xs[i]) * 3u;
      o += vec3(sky_rgb[k], sky_rgb[k + 1u], sky_rgb[k + 2u]) * (wx[i] * wy[j]);
    }
  return o * P.sky.w;
}

// --- geometry helpers ---
vec3 vertex_pos(uint i) { return verts[i].pos_u.xyz; }

struct Hit {
  float t, u, v;
  uint tri;
  bool front;
  vec3 ng;  // unit normal of the counter-clockwise side
};

Hit intersect(vec3 org, vec3 dir) {
  Hit h;
  uint slot = traverse(P.counts.y, org, dir, 0.0, kInf, false, h.t, h.u, h.v);
  if (slot == GPU_NO_ROOT) {
    h.t = -1.0;
    return h;
  }
  h.tri = floatBitsToUint(tris[slot].v0.w);
  uvec4 idx = shade_tris[h.tri].idx_mat;
  vec3 a = vertex_pos(idx.x);
  vec3 ng = cross(vertex_pos(idx.y) - a, vertex_pos(idx.z) - a);
  h.front = dot(dir, ng) < 0.0;
  h.ng = normalize(ng);
  return h;
}

bool occluded(vec3 org, vec3 dir, float tfar) {
  float t, u, v;
  return traverse(P.counts.y, org, dir, 0.0, tfar, true, t, u, v) != GPU_NO_ROOT;
}

vec3 offset_origin(vec3 p, vec3 ng) {
  float pmag = max(max(abs(p.x), abs(p.y)), max(abs(p.z), 1.0));
  return p + ng * (P.misc.y * pmag);
}

bool is_black(vec3 c) { return c.x <= 0.0 && c.y <= 0.0 && c.z <= 0.0; }

// --- thin glass (bake/trace/probe_rays.cpp transmittance, path_gather.cpp cross_glass) ---
const int kMaxGlassCrossings = 16;
float transmission_of(uint tri) { return uintBitsToFloat(shade_mats[shade_tris[tri].idx_mat.w].tex.w); }

vec3 transmittance(vec3 org, vec3 dir, float tfar) {
  if (P.misc.z == 0.0) return occluded(org, dir, tfar) ? vec3(0.0) : vec3(1.0);
  vec3 through = vec3(1.0);
  float tnear = 0.0;
  for (int crossing = 0; crossing <= kMaxGlassCrossings; ++crossing) {
    float t, u, v;
    uint slot = traverse(P.counts.y, org, dir, tnear, tfar, false, t, u, v);
    if (slot == GPU_NO_ROOT) return through;
    uint tri = floatBitsToUint(tris[slot].v0.w);
    if (!(transmission_of(tri) > 0.0) || crossing == kMaxGlassCrossings) return vec3(0.0);
    Surface s = surface_sample(tri, u, v, 0.0, 1.0);
    through = through * s.albedo * s.transmission;
    if (max(max(through.x, through.y), through.z) <= 0.0) return vec3(0.0);
    vec3 p = org + dir * t;
    tnear = t + P.misc.y * max(max(abs(p.x), abs(p.y)), max(abs(p.z), 1.0));
    if (!(tnear < tfar)) return through;
  }
  return vec3(0.0);
}

// --- punctual lights (kernels/shade.cpp sample_light, bake/trace/probe_rays.cpp shade_punctual) ---
bool sample_light(GpuLight l, vec3 p, out vec3 to_light, out float dist, out vec3 illum) {
  int type = int(l.dir_type.w);
  vec3 travel = l.dir_type.xyz;
  if (type == 0) {
    to_light = -travel;
    dist = kInf;
    illum = l.color.rgb;
  } else {
    vec3 d = l.pos_range.xyz - p;
    float d2 = dot(d, d);
    to_light = vec3(0.0, 1.0, 0.0);
    dist = 0.0;
    illum = vec3(0.0);
    if (d2 <= 0.0) return false;
    dist = sqrt(d2);
    to_light = d * (1.0 / dist);
    float atten = 1.0 / d2;
    float range = l.pos_range.w;
    if (range > 0.0) {
      float r = dist / range;
      atten *= clamp(1.0 - r * r * r * r, 0.0, 1.0);
    }
    if (type == 2) {
      float cd = dot(travel, -to_light);
      float a = clamp(cd * l.cone.x + l.cone.y, 0.0, 1.0);
      atten *= a * a;
    }
    illum = l.color.rgb * atten;
  }
  return illum.x > 0.0 || illum.y > 0.0 || illum.z > 0.0;
}

vec3 shade_punctual(vec3 shadow_org, vec3 n, vec3 ng, vec3 albedo, float u_choice, inout uint shadow_rays) {
  int count = int(P.counts.z);
  if (count <= 0 || dot(albedo, albedo) <= 0.0) return vec3(0.0);
  bool one = P.flags.x != 0u && count > 1;
  int first = one ? min(count - 1, int(u_choice * float(count))) : 0;
  int last = one ? first + 1 : count;
  vec3 e = vec3(0.0);
  for (int li = first; li < last; ++li) {
    vec3 l, illum;
    float dist;
    if (!sample_light(lights[li], shadow_org, l, dist, illum)) continue;
    if (dot(n, l) <= 0.0 || dot(ng, l) <= 0.0) continue;
    float tfar = isinf(dist) ? kInf : dist * (1.0 - 1e-4);
    ++shadow_rays;
    if (P.misc.z != 0.0) {  // through glass: the light arrives tinted
      illum = illum * transmittance(shadow_org, l, tfar);
      if (max(max(illum.x, illum.y), illum.z) <= 0.0) continue;
    } else if (occluded(shadow_org, l, tfar)) {
      continue;
    }
    e += illum * dot(n, l);
  }
  return albedo * e * ((one ? float(count) : 1.0) / kPi);
}

float power_heuristic(float a, float b) {
  float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}
float area_to_solid_angle_pdf(float pdf_area, float dist, float cos_light) {
  return cos_light > 0.0 ? pdf_area * dist * dist / cos_light : 0.0;
}

#include "path_emitters.glsl"

// The ray that found a hit, as MIS sees it (path_gather.cpp RayMis): x its density, y the
// emitters' and z the sky map's share of the light technique that could sample its direction.
// MIS weight of emission `ray` found `dist` from its vertex.
float emission_weight(Hit hit, vec3 dir, vec3 ng, vec3 ray, float dist) {
  float pdf_area = P.counts.w > 0u ? shade_tris[hit.tri].extra.y : 0.0;
  if (!(ray.x > 0.0 && pdf_area > 0.0 && ray.y > 0.0)) return 1.0;
  return power_heuristic(ray.x, ray.y * area_to_solid_angle_pdf(pdf_area, dist, -dot(dir, ng)));
}
// MIS weight of the sky `ray` found along dir.
float sky_weight(vec3 dir, vec3 ray) {
  if (!(ray.x > 0.0 && ray.z > 0.0)) return 1.0;
  return power_heuristic(ray.x, ray.z * sky_pdf(dir));
}

uint glass_stream(int k) { return (1u << 20) | uint(k); }

// Thin glass at `hit`: pass straight on with probability t, tinted (bake/trace/path_gather.cpp
// cross_glass). False when the path ends.
bool cross_glass(inout vec3 org, vec3 dir, inout Hit hit, uint64_t key, vec3 ray, inout int crossings,
                 inout int draws, inout vec3 throughput, inout vec3 radiance, inout float seg, inout float cone_width,
                 inout uint bounce_rays) {
  for (;;) {
    GpuShadeMaterial m = shade_mats[shade_tris[hit.tri].idx_mat.w];
    if (!(uintBitsToFloat(m.tex.w) > 0.0) || crossings >= kMaxGlassCrossings) return true;
    vec3 ng_far = hit.front ? -hit.ng : hit.ng;
    float width = cone_width + P.misc.x * hit.t;
    Surface s = surface_sample(hit.tri, hit.u, hit.v, width, dot(dir, ng_far));
    if (s.transmission < 1.0 && rng_uniform(key, glass_stream(draws++)) >= s.transmission) return true;
    ++crossings;
    vec3 p = org + dir * hit.t;
    cone_width = width;
    if (!is_black(s.emission) && (hit.front || m.tex.z != 0u))
      radiance += throughput * s.emission * emission_weight(hit, dir, -ng_far, ray, seg + hit.t);
    throughput *= s.albedo;
    if (is_black(throughput)) return false;
    seg += hit.t;
    org = offset_origin(p, ng_far);
    hit = intersect(org, dir);
    ++bounce_rays;
    if (hit.t < 0.0) {
      radiance += throughput * sky_radiance(dir) * sky_weight(dir, ray);
      return false;
    }
  }
  return true;
}

// Radiance leaving the surface at `hit` towards org (bake/trace/path_gather.cpp path_radiance).
// Cosine-weighted direction about n (kernels/path.cpp sample_cosine_hemisphere): Malley's method,
// Duff et al.'s basis.
vec3 cosine_direction(vec3 n, float u1, float u2) {
  float r = sqrt(u1), phi = 2.0 * kPi * u2;
  float x = r * cos(phi), y = r * sin(phi), z = sqrt(max(0.0, 1.0 - u1));
  float sg = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;  // copysign(1, n.z)
  float a = -1.0 / (sg + n.z), b = n.x * n.y * a;
  vec3 t = vec3(1.0 + sg * n.x * n.x * a, sg * b, -sg * n.x), bt = vec3(b, sg + n.y * n.y * a, -n.y);
  return normalize(t * x + bt * y + n * z);
}

#ifdef PATH_PROBE_FIELD
// Where the path that path_radiance is tracing would have ended at its first hit: its radiance up to
// there, the weight of the probes' irradiance (throughput x albedo), the point and its normal. Unset
// where it never reached one to end at (its whole radiance then).
struct FirstHit {
  vec3 radiance, weight, p, n;
};
FirstHit ended_at;
bool ended_set = false;
// Path i's first hit for probe_field_ended.comp: (radiance + `light`, p.x), (weight, p.y), (n, p.z);
// a zero weight and normal where the probes add nothing (the path's `whole` radiance then).
void write_first_hit(uint i, vec3 whole, vec3 light) {
  if (!ended_set) {
    first_hits[3u * i] = vec4(whole + light, 0.0);
    first_hits[3u * i + 1u] = vec4(0.0);
    first_hits[3u * i + 2u] = vec4(0.0);
    return;
  }
  first_hits[3u * i] = vec4(ended_at.radiance + light, ended_at.p.x);
  first_hits[3u * i + 1u] = vec4(ended_at.weight, ended_at.p.y);
  first_hits[3u * i + 2u] = vec4(ended_at.n, ended_at.p.z);
}
#endif

vec3 path_radiance(vec3 org, vec3 dir, Hit hit, uint64_t key, vec3 first, inout uint shadow_rays,
                   inout uint bounce_rays) {
  bool have_emitters = P.counts.w > 0u;
  int bounces = int(P.flags.y);
  vec3 radiance = vec3(0.0), throughput = vec3(1.0);
  vec3 ray = first;
  float cone_width = 0.0;
  bool glass = P.misc.z != 0.0;
  int crossings = 0, draws = 0;
  for (int depth = 0;; ++depth) {
    float seg = 0.0;  // distance from the last vertex to the glass the path passed through
    if (glass && !cross_glass(org, dir, hit, key, ray, crossings, draws, throughput, radiance, seg, cone_width,
                              bounce_rays))
      break;
    bool double_sided = shade_mats[shade_tris[hit.tri].idx_mat.w].tex.z != 0u;
    if (!hit.front && !double_sided) break;
    vec3 ng = hit.front ? hit.ng : -hit.ng;
    vec3 p = org + dir * hit.t;
    cone_width += P.misc.x * hit.t;
    Surface surf = surface_sample(hit.tri, hit.u, hit.v, cone_width, dot(dir, ng));
    vec3 n = dot(surf.normal, surf.normal) == 0.0 ? ng : surf.normal;
    if (dot(n, ng) < 0.0) n = -n;
    if (!is_black(surf.emission)) radiance += throughput * surf.emission * emission_weight(hit, dir, ng, ray, seg + hit.t);
    if (depth > bounces || is_black(surf.albedo)) break;
    vec3 shadow_org = offset_origin(p, ng);
    float u_light = P.flags.x != 0u ? rng_uniform(key, stream_of(depth, 0u)) : 0.0;
    radiance += throughput * shade_punctual(shadow_org, n, ng, surf.albedo, u_light, shadow_rays);
#ifdef PATH_PROBE_FIELD
    // The rest of the path in the probes' light, except at an emitter's own surface (path_radiance's
    // rule); probe_field_ended.comp reads the probes.
    if (depth == 0 && is_black(surf.emission)) {
      ended_at = FirstHit(radiance, throughput * surf.albedo, p, n);
      ended_set = true;
    }
#endif
    if (have_emitters) radiance += throughput * sample_emitter(n, ng, surf.albedo, shadow_org, key, depth, shadow_rays);
    if (depth == bounces && P.flags.w == 0u) break;
    vec3 w = cosine_direction(n, rng_uniform(key, stream_of(depth, 4u)), rng_uniform(key, stream_of(depth, 5u)));
    float cos_n = dot(w, n);
    if (dot(w, ng) <= 0.0 || cos_n <= 0.0) break;
    throughput *= surf.albedo;
    if (depth + 1 >= int(P.flags.z)) {
      float survive = clamp(max(max(throughput.x, throughput.y), throughput.z), 0.05, 0.95);
      if (rng_uniform(key, stream_of(depth, 6u)) >= survive) break;
      throughput *= 1.0 / survive;
    }
    ray = vec3(cos_n / kPi, 1.0, 0.0);
    org = shadow_org;
    dir = w;
    hit = intersect(org, dir);
    ++bounce_rays;
    if (hit.t < 0.0) {
      radiance += throughput * sky_radiance(dir);
      break;
    }
  }
  return radiance;
}

// The probe-feedback gather's hit (bake/trace/probe_rays.cpp trace_probe_rays): shading normal, albedo and
// emission + direct light, no path.
void feedback_hit(vec3 org, vec3 dir, Hit hit, uint64_t key, inout GpuPathOut o, inout uint shadow_rays) {
  vec3 ng = hit.front ? hit.ng : -hit.ng;
  Surface surf = surface_sample(hit.tri, hit.u, hit.v, P.misc.x * hit.t, dot(dir, ng));
  if (transmission_of(hit.tri) > 0.0) surf.albedo = surf.albedo * (1.0 - surf.transmission);  // reflects what it does not let through
  vec3 n = dot(surf.normal, surf.normal) == 0.0 ? ng : surf.normal;
  if (dot(n, ng) < 0.0) n = -n;
  o.normal_kind = vec4(n, 1.0);
  o.albedo = vec4(surf.albedo, 0.0);
  vec3 shadow_org = offset_origin(org + dir * hit.t, ng);
  float u = (P.flags.x != 0u && P.counts.z > 1u) ? rng_uniform(key, 7u) : 0.0;
  o.radiance.rgb = surf.emission + shade_punctual(shadow_org, n, ng, surf.albedo, u, shadow_rays);
}

// What integrate.comp reads of a ray (ProbeIntegrator::integration_sample): misses at the max
// distance, back faces pulled in by 0.9, the depth clamped to the max distance.
GpuRaySample integration_sample(GpuPathOut o) {
  const float max_distance = push.params.x;
  float depth = o.dir_t.w;
  const int kind = int(o.normal_kind.w);
  if (kind == 0)
    depth = max_distance;
  else if (kind == 2)
    depth *= 0.9;
  depth = min(depth, max_distance);
  return GpuRaySample(vec4(o.dir_t.xyz, depth), vec4(o.radiance.xyz, 0.0));
}

// Mode 2: path r of a reference point (bake/preview/reconstruction_check.cpp reference_path: the
// check's stratified cosine-weighted directions, m x m strata first, push.samples.y = m), traced by
// main() as trace_radiance traces it; its brief carries the path's half of the strata's
// checkerboard (counts.z) and whether it was traced (counts.w: 0 below the geometric surface).
// Paths in point order. False: below the surface, nothing to trace.
bool reference_ray(uint i, out vec3 org, out vec3 dir, out uint64_t key, out uint half_index) {
  const uint rays = push.samples.w, m = push.samples.y;
  const uint point = i / rays, r = i - point * rays;
  const GpuReferencePoint pt = points[point];
  const uint64_t point_key = uint64_t(pt.key.x) | (uint64_t(pt.key.y) << 32);
  const uint64_t salt = uint64_t(pt.key.z) | (uint64_t(pt.key.w) << 32);
  const uint64_t path_key = rng_hash(point_key, uint64_t(r), 0UL, salt);
  precise float u1 = rng_uniform(path_key, 0u), u2 = rng_uniform(path_key, 1u);
  half_index = r & 1u;
  if (r < m * m) {
    u1 = (float(r % m) + u1) / float(m);
    u2 = (float(r / m) + u2) / float(m);
    half_index = (r % m + r / m) & 1u;
  }
  org = pt.origin.xyz;
  dir = cosine_direction(pt.n.xyz, min(u1, 0.99999994), min(u2, 0.99999994));
  key = rng_hash(path_key, 1UL, 0UL, 0UL);  // trace_radiance's
  return dot(dir, pt.ng.xyz) > 0.0;
}

void main() {
  const uint lane_i = GIBAKE_FLAT_INVOCATION;
  if (lane_i >= P.counts.x) return;
  // One intersect and one path_radiance for every mode, so that the kernel's code is not doubled.
  const bool reference = P.sky_map.z == 2u;
  uint i = lane_i, half_index = 0u;
  vec3 org, dir;
  uint64_t key;
  GpuPathRay ray = GpuPathRay(vec4(0.0), vec4(0.0), uvec4(0u));
  uint shadow_rays = 0u, bounce_rays = 0u, back = 0u;
  const float sky_share = P.misc.w;
  // The ray as MIS sees it: a probe ray paired with the probe's light sample (path gather), a
  // reference path paired with its point's emitter sample, else nothing else samples what it finds.
  vec3 first = vec3(0.0, 1.0, 0.0);
  vec3 surface_light = vec3(0.0);
  if (reference) {
    const bool traced = reference_ray(lane_i, org, dir, key, half_index);
    if (P.sky_map.w != 0u) {  // path r of its point paired with emitter sample r (trace_surface_radiance)
      const uint rays = push.samples.w, point = lane_i / rays, r = lane_i - point * rays;
      const GpuReferencePoint pt = points[point];
      const uint64_t point_key = uint64_t(pt.key.x) | (uint64_t(pt.key.y) << 32);
      const uint64_t salt = uint64_t(pt.key.z) | (uint64_t(pt.key.w) << 32);
      const uint64_t shift = rng_hash(point_key, 0xFFFFFFFEUL, 0UL, salt);  // kernels::kProbeLightShiftRay
      surface_light =
          sample_surface_light(pt.origin.xyz, pt.n.xyz, pt.ng.xyz, probe_light_uniforms(shift, r, rays), shadow_rays);
      first = vec3(max(0.0, dot(dir, pt.n.xyz)) / kPi, 1.0, 0.0);
    }
    if (!traced) {
      briefs[i] = GpuPathBrief(vec4(surface_light, -1.0), uvec4(shadow_rays, 0u, half_index, 0u));
#ifdef PATH_PROBE_FIELD
      write_first_hit(i, vec3(0.0), surface_light);
#endif
      return;
    }
  } else {
    ray = rays[lane_i];
    // The ray's own position in the batch: its lane's, moved within the probe's block of rays.
    const uint rpp = push.samples.w, lane = (push.samples.y + lane_i) % rpp;
    i = lane_i - lane + order[lane];
    org = ray.org.xyz;
    dir = ray.dir.xyz;
    key = uint64_t(ray.key.x) | (uint64_t(ray.key.y) << 32);
  }
  GpuPathOut o;
  o.dir_t = vec4(dir, -1.0);
  o.normal_kind = vec4(0.0);
  o.radiance = vec4(0.0);
  o.albedo = vec4(0.0);
  // The probe's emitter sample paired with this ray (path gather only): its emission is then MIS-weighted.
  const bool probe_lights = P.sky_map.w != 0u && P.sky_map.z == 0u;
  GpuRaySample light = GpuRaySample(vec4(0.0), vec4(0.0));
  if (probe_lights) first = vec3(kProbeRayPdf, 1.0 - sky_share, sky_share);
  if (probe_lights) {  // sample r of the probe's n (push.samples.w rays a probe) in this batch
    const uint g = push.samples.y + i, n = push.samples.w;
    const uint64_t shift = uint64_t(ray.key.z) | (uint64_t(ray.key.w) << 32);
    light = sample_probe_light(org, probe_light_uniforms(shift, g % n, n), shadow_rays);
  }
  Hit hit = intersect(org, dir);
  if (hit.t < 0.0) {
    o.radiance.rgb = sky_radiance(dir) * sky_weight(dir, first);  // kind 0: miss
  } else {
    o.dir_t.w = hit.t;
    vec3 ng = hit.front ? hit.ng : -hit.ng;
    bool double_sided = shade_mats[shade_tris[hit.tri].idx_mat.w].tex.z != 0u;
    if (!hit.front && !double_sided && !reference) {  // trace_radiance's path finds them black itself
      o.normal_kind = vec4(ng, 2.0);
      back = 1u;
    } else if (P.sky_map.z == 1u) {
      feedback_hit(org, dir, hit, key, o, shadow_rays);
    } else {
      o.normal_kind = vec4(ng, 1.0);
      o.radiance.rgb = path_radiance(org, dir, hit, key, first, shadow_rays, bounce_rays);
    }
  }
  if (reference) {
    briefs[i] = GpuPathBrief(vec4(o.radiance.xyz + surface_light, o.dir_t.w),
                             uvec4(shadow_rays, bounce_rays, half_index, 1u));
#ifdef PATH_PROBE_FIELD
    write_first_hit(i, o.radiance.xyz, surface_light);
#endif
    return;
  }
  o.counts = uvec4(shadow_rays, bounce_rays, back, 0u);
  if (push.samples.z != 0u)
    briefs[i] = GpuPathBrief(vec4(o.radiance.xyz, o.dir_t.w), uvec4(o.counts.xyz, uint(o.normal_kind.w)));
  else
    outs[i] = o;
  if (probe_lights) light_out[i] = light;
  if (push.samples.x != 0u) {
    if (probe_lights) {  // a probe's samples: its rays, then their emitter samples (push.samples.w rays each)
      const uint g = push.samples.y + i, n = push.samples.w;
      samples[2u * n * (g / n) + g % n] = integration_sample(o);
      samples[2u * n * (g / n) + n + g % n] = light;
    } else {
      samples[push.samples.y + i] = integration_sample(o);
    }
  }
}

#endif  // GIBAKE_PATH_KERNEL_GLSL
