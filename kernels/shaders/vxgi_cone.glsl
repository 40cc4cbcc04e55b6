// gibake voxel-GI cone tracer for engines: the GLSL twin of the loader's CPU tracer
// (io/loader/src/vxgi.cpp sample / sample_cone, io/loader/src/vxgi_cone.cpp cone_trace /
// cone_trace_diffuse), checked against it on lavapipe (tests/vulkan/gpu_vxgi_test.cpp).
// Format and conventions: docs/FORMAT.md "gibake_vxgi_volume" and "Cone tracer".
//
// The includer provides the file's volumes (clipmaps, 0 = finest) and their storage, in any form
// (SSBOs, 3D textures with texelFetch, ...):
//   uint  gibake_vxgi_clipmap_count();
//   GibakeVxgiVolume gibake_vxgi_clipmap(uint k);  // with .index = k
//   vec4  gibake_vxgi_fetch(uint clipmap, uint level, uint face, ivec3 c);  // c is inside the level's grid
//   float gibake_vxgi_fetch_sdf(uint clipmap, ivec3 c);  // only with #define GIBAKE_VXGI_SDF before
//                                                        // the include: vxgi_sdf of level-0 voxel c
// With GIBAKE_VXGI_SDF and GibakeConeOptions.use_sdf, cones skip empty space as the CPU tracer
// does with ConeOptions::use_sdf (the default); without, it equals the CPU with use_sdf = false.
// Faces: 0..5 = +X, -X, +Y, -Y, +Z, -Z (face +X: light leaving towards +X), rgb premultiplied.
// gibake_vxgi_index() gives the element index of the bake file's vxgi_radiance layout. A volume
// baked with --vxgi-precompute-cones (faces = 22) also holds the 16 precomputed cone directions as
// slices 6..21; gibake_vxgi_cone_trace_diffuse_precomputed reads them (the loader's
// ConeOptions::precomputed_cones).
//
// Units: world space in metres; p is the shaded point (the tracer offsets it along n itself, by
// start_offset level-0 voxels), n and dir are unit vectors. Cone results are premultiplied radiance
// (cd/m^2) and alpha; the diffuse functions return irradiance in lux (times the bake's fitted
// diffuse_scale of clipmap 0). Diffuse radiance for an albedo is albedo * irradiance / pi.
// Example (samples/consumer/vxgi_shading.frag has the accessors over 3D textures):
//   #define GIBAKE_VXGI_SDF               // when the volumes have an SDF and it is bound
//   #include "gibake/vxgi_cone.glsl"
//   ... define gibake_vxgi_clipmap_count, gibake_vxgi_clipmap, gibake_vxgi_fetch, gibake_vxgi_fetch_sdf ...
//   GibakeConeOptions o = gibake_default_cone_options();
//   vec3 e = gibake_vxgi_cone_trace_diffuse(world_position, world_normal, o);  // lux
//   colour.rgb = albedo * e / 3.14159265;
#ifndef GIBAKE_VXGI_CONE_GLSL
#define GIBAKE_VXGI_CONE_GLSL

struct GibakeVxgiVolume {
  vec3 grid_min;        // gibake_vxgi_volume.grid_min
  float voxel_size;     // level 0
  ivec3 dims;           // level 0
  uint levels;
  vec3 sky;             // cd/m^2 beyond the volume
  float diffuse_scale;  // the bake's fitted factor (1 for raw cones)
  uint index;           // clipmap index, handed back to the fetch functions
  bool has_sdf;         // the volume has a vxgi_sdf section
  uint faces;           // gibake_vxgi_volume.faces of the storage: 6, or 22 with the precomputed cone slices
};

struct GibakeConeOptions {
  float step_scale;            // 1
  float start_offset;          // 1 (voxels along n)
  float alpha_stop;            // 0.99
  float max_distance;          // 0: until the cone leaves the volume
  float self_occlusion_limit;  // 0.5
  bool use_sdf;                // true: SDF steps (needs GIBAKE_VXGI_SDF and a volume with an SDF)
};

GibakeConeOptions gibake_default_cone_options() { return GibakeConeOptions(1.0, 1.0, 0.99, 0.0, 0.5, true); }

uint gibake_vxgi_clipmap_count();
GibakeVxgiVolume gibake_vxgi_clipmap(uint k);
vec4 gibake_vxgi_fetch(uint clipmap, uint level, uint face, ivec3 c);

// Halving `level` times, rounding up, is one rounded-up division by 2^level. No loop: Mesa's
// llvmpipe (lavapipe) caps the loop iterations of a whole invocation at 65535 and then leaves every
// loop after one pass, and this runs for every texel fetched (the nested loops here and in
// gibake_vxgi_index used up that budget within the sixth cone of a diffuse query over clipmaps).
ivec3 gibake_vxgi_level_dims(GibakeVxgiVolume v, uint level) {
  return (v.dims + ((1 << int(level)) - 1)) >> int(level);
}

// Element index of texel c (inside the level) in the volume's vxgi_radiance section.
uint gibake_vxgi_index(GibakeVxgiVolume v, uint level, uint face, ivec3 c) {
  uint offset = 0u;
  for (uint l = 0u; l < level; ++l) {
    ivec3 d = gibake_vxgi_level_dims(v, l);
    offset += v.faces * uint(d.x * d.y * d.z);
  }
  ivec3 d = gibake_vxgi_level_dims(v, level);
  return offset + face * uint(d.x * d.y * d.z) + uint(c.x + d.x * (c.y + d.y * c.z));
}

vec4 gibake_vxgi_texel(GibakeVxgiVolume v, uint level, uint face, ivec3 c) {
  ivec3 d = gibake_vxgi_level_dims(v, level);
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, d))) return vec4(0.0);
  return gibake_vxgi_fetch(v.index, level, face, c);
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

// What cone slice `slice` (6..21, a precomputed direction) holds at p, fractional level lod: the
// trilinear sample of that one slice, mips blended (the loader's VxgiVolume::sample_slice).
vec4 gibake_vxgi_sample_slice(GibakeVxgiVolume v, float lod, uint slice, vec3 dir, vec3 p) {
  lod = clamp(lod, 0.0, float(v.levels - 1u));
  uint l0 = uint(lod);
  float t = lod - float(l0);
  vec4 s = gibake_vxgi_sample(v, l0, slice, p, dir);
  if (t > 0.0 && l0 + 1u < v.levels) s += t * (gibake_vxgi_sample(v, l0 + 1u, slice, p, dir) - s);
  return s;
}

// A cone reads its precomputed slice when it has one (slice != 0) and the volume stores it, else the faces.
vec4 gibake_vxgi_cone_sample(GibakeVxgiVolume v, uint slice, float lod, vec3 dir, vec3 p) {
  return slice != 0u && slice < v.faces ? gibake_vxgi_sample_slice(v, lod, slice, dir, p)
                                        : gibake_vxgi_sample_cone(v, lod, dir, p);
}

#ifdef GIBAKE_VXGI_SDF
float gibake_vxgi_fetch_sdf(uint clipmap, ivec3 c);

// Distance (m) from p to the nearest opaque level-0 voxel: trilinear over the voxel centres, clamped
// to the outermost ones (the loader's VxgiVolume::sdf).
float gibake_vxgi_sdf(GibakeVxgiVolume v, vec3 p) {
  vec3 c = min(max((p - v.grid_min) / v.voxel_size - 0.5, vec3(0.0)), vec3(v.dims - 1));
  ivec3 base = clamp(ivec3(c), ivec3(0), max(v.dims - 2, ivec3(0)));
  vec3 f = mix(vec3(0.0), c - vec3(base), greaterThan(v.dims, ivec3(1)));
  float acc = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    ivec3 up = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    vec3 wv = mix(1.0 - f, f, bvec3(up));
    float w = wv.x * wv.y * wv.z;
    acc += w * gibake_vxgi_fetch_sdf(v.index, min(base + up, v.dims - 1));
  }
  return max(acc, 0.0);
}
#endif

bool gibake_vxgi_overlaps(GibakeVxgiVolume v, vec3 q, float radius) {
  vec3 lo = v.grid_min - radius, hi = v.grid_min + vec3(v.dims) * v.voxel_size + radius;
  return all(greaterThanEqual(q, lo)) && all(lessThanEqual(q, hi));
}

bool gibake_vxgi_contains(GibakeVxgiVolume v, vec3 q) { return gibake_vxgi_overlaps(v, q, 0.0); }

// Distance from q to the nearest face of the volume's box, inwards (negative outside).
float gibake_vxgi_inner_margin(GibakeVxgiVolume v, vec3 q) {
  vec3 lo = v.grid_min, hi = v.grid_min + vec3(v.dims) * v.voxel_size;
  vec3 m = min(q - lo, hi - q);
  return min(m.x, min(m.y, m.z));
}

// Clipmap k's sample for a footprint at q, blended towards k + 1 within two texels of k's border;
// `voxel` receives the texel size read.
vec4 gibake_vxgi_clipmap_sample(uint k, uint slice, float footprint, vec3 dir, vec3 q, out float voxel) {
  GibakeVxgiVolume v = gibake_vxgi_clipmap(k);
  float lod = log2(footprint / v.voxel_size);
  vec4 s = gibake_vxgi_cone_sample(v, slice, lod, dir, q);
  voxel = v.voxel_size * exp2(min(max(lod, 0.0), float(v.levels - 1u)));
  if (k + 1u < gibake_vxgi_clipmap_count()) {
    float w = 1.0 - clamp((gibake_vxgi_inner_margin(v, q) - 0.5 * footprint) / (2.0 * voxel), 0.0, 1.0);
    if (w > 0.0) {
      GibakeVxgiVolume c = gibake_vxgi_clipmap(k + 1u);
      s += w * (gibake_vxgi_cone_sample(c, slice, log2(footprint / c.voxel_size), dir, q) - s);
    }
  }
  return s;
}

// One cone (full apex angle `aperture`) over every clipmap: radiance (cd/m^2) in rgb, opacity in a.
// slice: 0 (the six faces), or 6..21 for one of the 16 precomputed cone directions.
vec4 gibake_vxgi_cone_trace_slice(vec3 p, vec3 n, vec3 dir, float aperture, GibakeConeOptions o, uint slice) {
  dir = normalize(dir);
  uint count = gibake_vxgi_clipmap_count();
  uint base = 0u;  // the finest clipmap holding p: the cone's own scale
  while (base + 1u < count && !gibake_vxgi_contains(gibake_vxgi_clipmap(base), p)) ++base;
  GibakeVxgiVolume outer = gibake_vxgi_clipmap(count - 1u);
  float v0 = gibake_vxgi_clipmap(base).voxel_size;
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
    if (!gibake_vxgi_overlaps(outer, q, 0.5 * diameter)) {
      color += (1.0 - alpha) * outer.sky;
      break;
    }
    ++steps;
    float footprint = diameter;
    if (o.self_occlusion_limit > 0.0) footprint = min(footprint, max(v0, o.self_occlusion_limit * dist));
    uint k = base;  // the finest clipmap whose box holds the footprint
    while (k + 1u < count && gibake_vxgi_inner_margin(gibake_vxgi_clipmap(k), q) < 0.5 * footprint) ++k;
    float voxel;
    vec4 s = gibake_vxgi_clipmap_sample(k, slice, footprint, dir, q, voxel);
    float step_len = max(0.5 * v0, o.step_scale * footprint);
    float a = clamp(s.a, 0.0, 1.0);
    float ratio = step_len / voxel;
    float a_step = a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - a, ratio);
    float scale = a > 1e-6 ? a_step / a : ratio;
    color += (1.0 - alpha) * max(s.rgb, vec3(0.0)) * scale;
    alpha += (1.0 - alpha) * a_step;
    float advance = step_len;
#ifdef GIBAKE_VXGI_SDF
    if (o.use_sdf) {
      uint j = count - 1u;  // the finest clipmap containing q (the coarsest otherwise)
      for (uint m = count - 1u; m > base; --m)
        if (gibake_vxgi_contains(gibake_vxgi_clipmap(m - 1u), q)) j = m - 1u;
      GibakeVxgiVolume sv = gibake_vxgi_clipmap(j);
      float reach = gibake_vxgi_sdf(sv, q) - 0.5 * diameter - footprint;
      advance = sv.has_sdf ? max(advance, reach) : advance;
    }
#endif
    dist += advance;
  }
  return vec4(color, min(alpha, 1.0));
}

vec4 gibake_vxgi_cone_trace(vec3 p, vec3 n, vec3 dir, float aperture, GibakeConeOptions o) {
  return gibake_vxgi_cone_trace_slice(p, n, dir, aperture, o, 0u);
}

// Irradiance (lux) at p for unit normal n: 6 cones of 60 degrees, weights pi/4 and 3 pi/20, times
// the finest clipmap's diffuse_scale.
vec3 gibake_vxgi_cone_trace_diffuse(vec3 p, vec3 n, GibakeConeOptions o) {
  const float kPi = 3.14159265358979;
  n = normalize(n);
  float sgn = n.z >= 0.0 ? 1.0 : -1.0;
  float fa = -1.0 / (sgn + n.z);
  float fc = n.x * n.y * fa;
  vec3 t = vec3(1.0 + sgn * n.x * n.x * fa, sgn * fc, -sgn * n.x);
  vec3 b = vec3(fc, sgn + n.y * n.y * fa, -n.y);
  vec3 e = (kPi / 4.0) * gibake_vxgi_cone_trace(p, n, n, kPi / 3.0, o).rgb;
  for (int k = 0; k < 5; ++k) {
    float phi = 2.0 * kPi * float(k) / 5.0;
    vec3 d = 0.5 * n + 0.8660254 * (cos(phi) * t + sin(phi) * b);
    e += (3.0 * kPi / 20.0) * gibake_vxgi_cone_trace(p, n, d, kPi / 3.0, o).rgb;
  }
  return e * gibake_vxgi_clipmap(0u).diffuse_scale;
}

// The 16 precomputed cone directions (VXGI's ConeTraceDiffuse): those above the surface, 50-degree
// cones, each reading its precomputed slice when the volume has them, cosine-weighted and
// normalised by the sum of the cosines (times pi), times diffuse_scale: the loader's
// cone_trace_diffuse with ConeOptions::precomputed_cones.
vec3 gibake_vxgi_cone_trace_diffuse_precomputed(vec3 p, vec3 n, GibakeConeOptions o) {
  const float kPi = 3.14159265358979;
  const vec3 dirs[16] = vec3[16](
      vec3(0.57735, 0.57735, 0.57735), vec3(0.57735, -0.57735, -0.57735), vec3(-0.57735, 0.57735, -0.57735),
      vec3(-0.57735, -0.57735, 0.57735), vec3(-0.903007, -0.182696, -0.388844), vec3(-0.903007, 0.182696, 0.388844),
      vec3(0.903007, -0.182696, 0.388844), vec3(0.903007, 0.182696, -0.388844), vec3(-0.388844, -0.903007, -0.182696),
      vec3(0.388844, -0.903007, 0.182696), vec3(0.388844, 0.903007, -0.182696), vec3(-0.388844, 0.903007, 0.182696),
      vec3(-0.182696, -0.388844, -0.903007), vec3(0.182696, 0.388844, -0.903007), vec3(-0.182696, 0.388844, 0.903007),
      vec3(0.182696, -0.388844, 0.903007));
  n = normalize(n);
  vec3 e = vec3(0.0);
  float sum = 0.0;
  for (uint i = 0u; i < 16u; ++i) {
    float cos_t = dot(n, dirs[i]);
    if (cos_t <= 0.0) continue;
    e += cos_t * gibake_vxgi_cone_trace_slice(p, n, dirs[i], 0.872665, o, 6u + i).rgb;
    sum += cos_t;
  }
  return (sum > 0.0 ? e * (kPi / sum) : vec3(0.0)) * gibake_vxgi_clipmap(0u).diffuse_scale;
}

// Deprecated name of gibake_vxgi_cone_trace_diffuse_precomputed, the same cones.
vec3 gibake_vxgi_cone_trace_diffuse_seed(vec3 p, vec3 n, GibakeConeOptions o) {
  return gibake_vxgi_cone_trace_diffuse_precomputed(p, n, o);
}

// ConeTraceSpecular: one cone about the mirror direction of `to_eye` (from p towards the viewer)
// in unit normal n, full apex angle max(0.05, roughness * pi / 2): premultiplied radiance (cd/m^2)
// and alpha, loader::cone_trace_specular's twin.
vec4 gibake_vxgi_cone_trace_specular(vec3 p, vec3 n, vec3 to_eye, float roughness, GibakeConeOptions o) {
  const float kPi = 3.14159265358979;
  n = normalize(n);
  vec3 e = normalize(to_eye);
  vec3 r = 2.0 * dot(n, e) * n - e;
  return gibake_vxgi_cone_trace(p, n, r, max(0.05, roughness * kPi * 0.5), o);
}

#endif  // GIBAKE_VXGI_CONE_GLSL
