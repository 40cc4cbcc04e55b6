// gibake voxel-GI cone tracer for engines: the GLSL twin of the loader's CPU tracer
// (io/loader/src/vxgi.cpp sample / sample_cone, io/loader/src/vxgi_cone.cpp cone_trace /
// cone_trace_diffuse), checked against it on lavapipe (tests/vulkan/gpu_vxgi_test.cpp).
// Format and conventions: docs/FORMAT.md "gibake_vxgi_volume" and "Cone tracer".
//
// The includer provides the storage, in any form (SSBO, 3D textures with texelFetch, ...):
//   vec4  gibake_vxgi_fetch(uint level, uint face, ivec3 c);  // texel; c is inside the level's grid
// This include traces without the SDF's empty-space steps: it equals the CPU tracer with
// ConeOptions::use_sdf = false (checked to 1e-6 on lavapipe). An SDF-stepping variant disagreed
// with the CPU on 18% of test values and was left out until that is understood.
// Faces: 0..5 = +X, -X, +Y, -Y, +Z, -Z (face +X: light leaving towards +X), rgb premultiplied.
// gibake_vxgi_index() gives the element index of the bake file's vxgi_radiance layout.
#ifndef GIBAKE_VXGI_CONE_GLSL
#define GIBAKE_VXGI_CONE_GLSL

struct GibakeVxgiVolume {
  vec3 grid_min;        // gibake_vxgi_volume.grid_min
  float voxel_size;     // level 0
  ivec3 dims;           // level 0
  uint levels;
  vec3 sky;             // cd/m^2 beyond the volume
  float diffuse_scale;  // the bake's fitted factor (1 for raw cones)
};

struct GibakeConeOptions {
  float step_scale;            // 1
  float start_offset;          // 1 (voxels along n)
  float alpha_stop;            // 0.99
  float max_distance;          // 0: until the cone leaves the volume
  float self_occlusion_limit;  // 0.5
};

GibakeConeOptions gibake_default_cone_options() { return GibakeConeOptions(1.0, 1.0, 0.99, 0.0, 0.5); }

vec4 gibake_vxgi_fetch(uint level, uint face, ivec3 c);

ivec3 gibake_vxgi_level_dims(GibakeVxgiVolume v, uint level) {
  ivec3 d = v.dims;
  for (uint l = 0u; l < level; ++l) d = (d + 1) / 2;
  return d;
}

// Element index of texel c (inside the level) in the vxgi_radiance section.
uint gibake_vxgi_index(GibakeVxgiVolume v, uint level, uint face, ivec3 c) {
  uint offset = 0u;
  for (uint l = 0u; l < level; ++l) {
    ivec3 d = gibake_vxgi_level_dims(v, l);
    offset += 6u * uint(d.x * d.y * d.z);
  }
  ivec3 d = gibake_vxgi_level_dims(v, level);
  return offset + face * uint(d.x * d.y * d.z) + uint(c.x + d.x * (c.y + d.y * c.z));
}

vec4 gibake_vxgi_texel(GibakeVxgiVolume v, uint level, uint face, ivec3 c) {
  ivec3 d = gibake_vxgi_level_dims(v, level);
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, d))) return vec4(0.0);
  return gibake_vxgi_fetch(level, face, c);
}

// Trilinear over the level's voxel centres (clamp to edge); along an axis with |dir| >= 0.9 the
// farther texel's colour is seen through the nearer one's alpha.
vec4 gibake_vxgi_sample(GibakeVxgiVolume v, uint level, uint face, vec3 p, vec3 dir) {
  float h = v.voxel_size * exp2(float(level));
  ivec3 d = gibake_vxgi_level_dims(v, level);
  ivec3 base;
  vec3 frac;
  for (int a = 0; a < 3; ++a) {
    float u = (p[a] - v.grid_min[a]) / h - 0.5;
    float c = min(max(u, 0.0), float(d[a] - 1));
    base[a] = min(int(c), max(d[a] - 2, 0));
    frac[a] = d[a] > 1 ? c - float(base[a]) : 0.0;
  }
  vec4 t[8];
  for (int corner = 0; corner < 8; ++corner)
    t[corner] = gibake_vxgi_texel(v, level, face, base + ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1));
  int n = 8;
  for (int a = 0; a < 3; ++a) {
    float f = frac[a];
    float da = dir[a];
    n /= 2;
    for (int i = 0; i < n; ++i) {
      vec4 lo = t[2 * i], hi = t[2 * i + 1];
      bool ordered = abs(da) >= 0.9;
      vec4 nearer = da >= 0.0 ? lo : hi;
      vec4 farther = da >= 0.0 ? hi : lo;
      float wn = da >= 0.0 ? 1.0 - f : f, wf = 1.0 - wn;
      float seen = ordered ? 1.0 - clamp(nearer.a, 0.0, 1.0) : 1.0;
      t[i] = vec4(wn * nearer.rgb + wf * farther.rgb * seen, wn * nearer.a + wf * farther.a);
    }
  }
  return t[0];
}

// What a cone along unit dir sees at p, fractional mip level lod: faces facing it, weights dir^2.
vec4 gibake_vxgi_sample_cone(GibakeVxgiVolume v, float lod, vec3 dir, vec3 p) {
  lod = clamp(lod, 0.0, float(v.levels - 1u));
  uint l0 = uint(lod);
  float t = lod - float(l0);
  vec4 acc = vec4(0.0);
  for (int a = 0; a < 3; ++a) {
    float w = dir[a] * dir[a];
    if (w == 0.0) continue;
    uint face = uint(2 * a + (dir[a] < 0.0 ? 0 : 1));
    vec4 s = gibake_vxgi_sample(v, l0, face, p, dir);
    if (t > 0.0 && l0 + 1u < v.levels) s += t * (gibake_vxgi_sample(v, l0 + 1u, face, p, dir) - s);
    acc += w * s;
  }
  return acc;
}

bool gibake_vxgi_overlaps(GibakeVxgiVolume v, vec3 q, float radius) {
  vec3 lo = v.grid_min - radius, hi = v.grid_min + vec3(v.dims) * v.voxel_size + radius;
  return all(greaterThanEqual(q, lo)) && all(lessThanEqual(q, hi));
}

// One cone (full apex angle `aperture`): radiance (cd/m^2) in rgb, opacity in a.
vec4 gibake_vxgi_cone_trace(GibakeVxgiVolume v, vec3 p, vec3 n, vec3 dir, float aperture, GibakeConeOptions o) {
  dir = normalize(dir);
  float v0 = v.voxel_size;
  float coef = 2.0 * tan(clamp(aperture, 1e-4, 3.1) * 0.5);
  vec3 start = p + n * (o.start_offset * v0);
  float max_dist = o.max_distance > 0.0 ? o.max_distance : 1e30;
  float dist = v0;
  vec3 color = vec3(0.0);
  float alpha = 0.0;
  for (uint steps = 0u; alpha < o.alpha_stop && steps < 4096u;) {
    vec3 q = start + dir * dist;
    if (dist > max_dist) break;
    float diameter = max(v0, coef * dist);
    if (!gibake_vxgi_overlaps(v, q, 0.5 * diameter)) {
      color += (1.0 - alpha) * v.sky;
      break;
    }
    ++steps;
    float footprint = diameter;
    if (o.self_occlusion_limit > 0.0) footprint = min(footprint, max(v0, o.self_occlusion_limit * dist));
    float lod = log2(footprint / v0);
    vec4 s = gibake_vxgi_sample_cone(v, lod, dir, q);
    float step_len = max(0.5 * v0, o.step_scale * footprint);
    float voxel = v0 * exp2(min(lod, float(v.levels - 1u)));
    float a = clamp(s.a, 0.0, 1.0);
    float ratio = step_len / voxel;
    float a_step = a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - a, ratio);
    float scale = a > 1e-6 ? a_step / a : ratio;
    color += (1.0 - alpha) * max(s.rgb, vec3(0.0)) * scale;
    alpha += (1.0 - alpha) * a_step;
    dist += step_len;
  }
  return vec4(color, min(alpha, 1.0));
}

// Irradiance (lux) at p for unit normal n: 6 cones of 60 degrees, weights pi/4 and 3 pi/20, times
// the volume's diffuse_scale.
vec3 gibake_vxgi_cone_trace_diffuse(GibakeVxgiVolume v, vec3 p, vec3 n, GibakeConeOptions o) {
  const float kPi = 3.14159265358979;
  n = normalize(n);
  float sgn = n.z >= 0.0 ? 1.0 : -1.0;
  float fa = -1.0 / (sgn + n.z);
  float fc = n.x * n.y * fa;
  vec3 t = vec3(1.0 + sgn * n.x * n.x * fa, sgn * fc, -sgn * n.x);
  vec3 b = vec3(fc, sgn + n.y * n.y * fa, -n.y);
  vec3 e = (kPi / 4.0) * gibake_vxgi_cone_trace(v, p, n, n, kPi / 3.0, o).rgb;
  for (int k = 0; k < 5; ++k) {
    float phi = 2.0 * kPi * float(k) / 5.0;
    vec3 d = 0.5 * n + 0.8660254 * (cos(phi) * t + sin(phi) * b);
    e += (3.0 * kPi / 20.0) * gibake_vxgi_cone_trace(v, p, n, d, kPi / 3.0, o).rgb;
  }
  return e * v.diffuse_scale;
}

#endif  // GIBAKE_VXGI_CONE_GLSL
