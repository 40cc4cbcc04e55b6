// Emitter sampling of path.comp, included there after the shading, geometry and glass helpers it
// calls (surface_sample, vertex_pos, alpha_keeps, transmittance, power_heuristic): the twins of
// bake/scene/emitters.cpp sample and bake/trace/path_gather.cpp pick_emitter_point, sample_emitter,
// pick_light, sample_probe_light, sample_surface_light, and kernels::probe_light_uniforms
// (kernels/path.cpp).
// --- emitters (bake/scene/emitters.cpp sample, bake/trace/path_gather.cpp pick_emitter_point,
// sample_emitter, pick_light, sample_probe_light, sample_surface_light) ---
// A point on an emissive triangle picked by power, seen from `from`: direction, distance, solid-angle
// density and emission towards `from`; false when it gives nothing.
bool pick_emitter_point(vec3 from, float u0, float u1, float u2, out vec3 w, out float dist, out float pdf,
                        out vec3 le) {
  w = vec3(0.0, 0.0, 1.0);
  dist = 0.0;
  pdf = 0.0;
  le = vec3(0.0);
  int count = int(P.counts.w);
  // upper_bound over the inclusive prefix sums
  int lo = 0, hi = count;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (emit_cdf[mid] <= u0) lo = mid + 1;
    else hi = mid;
  }
  uint tri = emit_tris[min(lo, count - 1)];
  float su = sqrt(u1);
  float eu = su * (1.0 - u2), ev = su * u2;
  GpuShadeTri st = shade_tris[tri];
  vec3 a = vertex_pos(st.idx_mat.x), b = vertex_pos(st.idx_mat.y), c = vertex_pos(st.idx_mat.z);
  vec3 pos = a * (1.0 - eu - ev) + b * eu + c * ev;
  vec3 en = normalize(cross(b - a, c - a));
  vec3 to = pos - from;
  dist = length(to);
  if (!(dist > 0.0)) return false;
  w = to * (1.0 / dist);
  GpuShadeMaterial m = shade_mats[st.idx_mat.w];
  float cos_l = -dot(en, w);
  if (m.tex.z != 0u) cos_l = abs(cos_l);
  if (cos_l <= 0.0) return false;
  uint slot = floatBitsToUint(st.extra.z);
  if (slot != 0u && !alpha_keeps(slot, eu, ev)) return false;
  le = surface_sample(tri, eu, ev, 0.0, 1.0).emission;
  if (is_black(le)) return false;
  pdf = area_to_solid_angle_pdf(st.extra.y, dist, cos_l);
  return pdf > 0.0;
}

vec3 sample_emitter(vec3 p_n, vec3 p_ng, vec3 albedo, vec3 shadow_org, uint64_t key, int depth, inout uint shadow_rays) {
  vec3 w, le;
  float dist, pdf_light;
  if (!pick_emitter_point(shadow_org, rng_uniform(key, stream_of(depth, 1u)), rng_uniform(key, stream_of(depth, 2u)),
                          rng_uniform(key, stream_of(depth, 3u)), w, dist, pdf_light, le))
    return vec3(0.0);
  float cos_x = dot(p_n, w);
  if (cos_x <= 0.0 || dot(p_ng, w) <= 0.0) return vec3(0.0);
  ++shadow_rays;
  vec3 through = transmittance(shadow_org, w, dist * (1.0 - 1e-3));
  if (is_black(through)) return vec3(0.0);
  float weight = power_heuristic(pdf_light, cos_x / kPi);
  vec3 l = albedo * le * (cos_x * weight / (kPi * pdf_light));
  return P.misc.z != 0.0 ? l * through : l;
}

// Density of a probe ray's direction: uniform over the sphere.
const float kProbeRayPdf = 1.0 / (4.0 * kPi);

// kernels::probe_light_uniforms: sample r of n, a shifted rank-1 lattice in 32-bit fixed point.
vec3 probe_light_uniforms(uint64_t shift_key, uint r, uint n) {
  uint x[3] = uint[3](n > 0u ? uint((uint64_t(r) << 32) / uint64_t(n)) : 0u, r * 3242174889u, r * 2447445414u);
  vec3 u;
  for (uint k = 0u; k < 3u; ++k) {
    x[k] += uint(rng_uniform(shift_key, k) * 16777216.0) << 8;
    u[k] = float(x[k] >> 8) * (1.0 / 16777216.0);
  }
  return u;
}

// --- the sky map's sampling (bake/scene/sky.cpp Sky::sample, Sky::pdf) ---
// The first prefix sum above u in cdf[at, at + n) (the last when rounding leaves none): its index,
// u's place in it and its probability.
int sky_pick(uint at, int n, float u, out float frac, out float p) {
  int lo = 0, hi = n;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (sky_cdf[at + uint(mid)] <= u) lo = mid + 1;
    else hi = mid;
  }
  int i = min(lo, n - 1);
  float below = i > 0 ? sky_cdf[at + uint(i - 1)] : 0.0;
  p = sky_cdf[at + uint(i)] - below;
  frac = p > 0.0 ? min((u - below) / p, 0.99999994) : 0.5;
  return i;
}

vec3 sky_sample(float u_row, float u_col, out float pdf) {
  int w = int(P.sky_map.x), h = int(P.sky_map.y);
  float fy, fx, p_row, p_col;
  int y = sky_pick(0u, h, u_row, fy, p_row);
  int x = sky_pick(uint(h) + uint(y) * uint(w), w, u_col, fx, p_col);
  float u = (float(x) + fx) / float(w), v = (float(y) + fy) / float(h);
  float theta = kPi * v, phi = 2.0 * kPi * (u - 0.5);
  float st = sin(theta);
  pdf = st > 0.0 ? p_row * p_col * float(w) * float(h) / (2.0 * kPi * kPi * st) : 0.0;
  return vec3(st * sin(phi), cos(theta), -st * cos(phi));
}

float sky_pdf(vec3 d) {
  int w = int(P.sky_map.x), h = int(P.sky_map.y);
  float u = 0.5 + atan(d.x, -d.z) / (2.0 * kPi);
  float v = acos(clamp(d.y, -1.0, 1.0)) / kPi;
  int x = clamp(int(u * float(w)), 0, w - 1), y = clamp(int(v * float(h)), 0, h - 1);
  float p_row = sky_cdf[uint(y)] - (y > 0 ? sky_cdf[uint(y - 1)] : 0.0);
  uint row = uint(h) + uint(y) * uint(w);
  float p_col = sky_cdf[row + uint(x)] - (x > 0 ? sky_cdf[row + uint(x - 1)] : 0.0);
  float st = sqrt(max(0.0, 1.0 - d.y * d.y));
  return st > 0.0 ? p_row * p_col * float(w) * float(h) / (2.0 * kPi * kPi * st) : 0.0;
}

// A light sample seen from `org` (path_gather.cpp pick_light): with u.x below the sky share
// (P.misc.w) a direction from the sky map, else an emitter point (u.x rescaled); its direction,
// radiance, distance and density with its technique's share. False: nothing (no shadow ray).
bool pick_light(vec3 org, vec3 u, out vec3 w, out vec3 le, out float tfar, out float pdf_light) {
  const float sky_share = P.misc.w;
  le = vec3(0.0);
  tfar = kInf;
  if (u.x < sky_share) {
    w = sky_sample(u.y, u.z, pdf_light);
    pdf_light *= sky_share;
    if (!(pdf_light > 0.0)) return false;
    le = sky_radiance(w);
    return !is_black(le);
  }
  float dist;
  if (!pick_emitter_point(org, (u.x - sky_share) / (1.0 - sky_share), u.y, u.z, w, dist, pdf_light, le)) return false;
  pdf_light *= 1.0 - sky_share;
  tfar = dist * (1.0 - 1e-3);
  return true;
}

// The probe's own light sample paired with its ray (path_gather.cpp sample_probe_light): radiance
// L w_light / (4 pi p_light).
GpuRaySample sample_probe_light(vec3 org, vec3 u, inout uint shadow_rays) {
  GpuRaySample s = GpuRaySample(vec4(0.0, 0.0, 1.0, 0.0), vec4(0.0));
  vec3 w, le;
  float tfar, pdf_light;
  if (!pick_light(org, u, w, le, tfar, pdf_light)) return s;
  s.dir_depth.xyz = w;
  ++shadow_rays;
  vec3 through = transmittance(org, w, tfar);
  if (is_black(through)) return s;
  float weight = power_heuristic(pdf_light, kProbeRayPdf);
  vec3 l = le * (weight / (4.0 * kPi * pdf_light));
  s.radiance.xyz = P.misc.z != 0.0 ? l * through : l;
  return s;
}

// A surface point's emitter sample (P.misc.w is 0 here) paired with a cosine-weighted reference
// path about n (path_gather.cpp sample_surface_light): L cos w / (pi p_light), w against the
// density cos / pi.
vec3 sample_surface_light(vec3 org, vec3 n, vec3 ng, vec3 u, inout uint shadow_rays) {
  vec3 w, le;
  float tfar, pdf_light;
  if (!pick_light(org, u, w, le, tfar, pdf_light)) return vec3(0.0);
  float cos_x = dot(n, w);
  if (cos_x <= 0.0 || dot(ng, w) <= 0.0) return vec3(0.0);
  ++shadow_rays;
  vec3 through = transmittance(org, w, tfar);
  if (is_black(through)) return vec3(0.0);
  float weight = power_heuristic(pdf_light, cos_x / kPi);
  vec3 l = le * (cos_x * weight / (kPi * pdf_light));
  return P.misc.z != 0.0 ? l * through : l;
}
