// Stack-based BVH traversal over GpuBvhNode / GpuTriangle with alpha-masked triangles, the GPU
// twin of Embree's rtcIntersect1 / rtcOccluded1 with bake/scene/prepare.cpp's alpha filter. The
// including shader declares the buffers `nodes`, `tris`, `alpha_tris`, `materials`, `textures`
// and `texels` before including this file.

// glTF wrap modes, as bake/scene/material.cpp wrap_coord.
int wrap_coord(int i, int n, uint mode) {
  if (mode == 33071u) return clamp(i, 0, n - 1);
  if (mode == 33648u) {
    int period = 2 * n;
    int m = i % period;
    if (m < 0) m += period;
    return m < n ? m : period - 1 - m;
  }
  int m = i % n;
  return m < 0 ? m + n : m;
}

// Bilinear alpha of a texture at (u, v), level 0, as bake/scene/material.cpp bilinear_taps and read_taps.
float texture_alpha(uint tex, float u, float v) {
  uvec4 info = textures[tex].info;
  int width = int(info.y), height = int(info.z);
  if (width <= 0 || height <= 0) return 1.0;
  float x = u * float(width) - 0.5, y = v * float(height) - 0.5;
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int x0 = int(fx), y0 = int(fy);
  uint ws = info.w & 0xFFFFu, wt = info.w >> 16;
  int xs0 = wrap_coord(x0, width, ws), xs1 = wrap_coord(x0 + 1, width, ws);
  int ys0 = wrap_coord(y0, height, wt), ys1 = wrap_coord(y0 + 1, height, wt);
  uint base = info.x;
  float a00 = float(texels[base + uint(ys0 * width + xs0)] >> 24) / 255.0;
  float a10 = float(texels[base + uint(ys0 * width + xs1)] >> 24) / 255.0;
  float a01 = float(texels[base + uint(ys1 * width + xs0)] >> 24) / 255.0;
  float a11 = float(texels[base + uint(ys1 * width + xs1)] >> 24) / 255.0;
  // Same order of sums as the CPU: (j, i) = (0,0), (0,1), (1,0), (1,1).
  float a = 0.0;
  a += ((1.0 - ax) * (1.0 - ay)) * a00;
  a += (ax * (1.0 - ay)) * a10;
  a += ((1.0 - ax) * ay) * a01;
  a += (ax * ay) * a11;
  return a;
}

// True when the alpha test keeps the hit (u, v) on masked triangle `slot` (1 + alpha index).
bool alpha_keeps(uint slot, float u, float v) {
  GpuAlphaTriangle at = alpha_tris[slot - 1u];
  GpuMaterial m = materials[at.a2_mat.y];
  float w0 = 1.0 - u - v;
  float a = m.base_color.w * (w0 * at.uv2_a01.z + u * at.uv2_a01.w + v * uintBitsToFloat(at.a2_mat.x));
  if (m.tex.x != GPU_NO_TEXTURE) {
    float s = w0 * at.uv01.x + u * at.uv01.z + v * at.uv2_a01.x;
    float t = w0 * at.uv01.y + u * at.uv01.w + v * at.uv2_a01.y;
    if (m.params.z != 0.0) {  // KHR_texture_transform: T * R * S
      float su = s * m.xform.z, sv = t * m.xform.w;
      float c = cos(m.params.x), sn = sin(m.params.x);
      s = c * su + sn * sv + m.xform.x;
      t = -sn * su + c * sv + m.xform.y;
    }
    a *= texture_alpha(m.tex.x, s, t);
  }
  return a >= m.params.y;
}

vec3 safe_inverse(vec3 d) {
  const float tiny = 1e-30;
  return vec3(abs(d.x) > tiny ? 1.0 / d.x : (d.x >= 0.0 ? 1e30 : -1e30),
              abs(d.y) > tiny ? 1.0 / d.y : (d.y >= 0.0 ? 1e30 : -1e30),
              abs(d.z) > tiny ? 1.0 / d.z : (d.z >= 0.0 ? 1e30 : -1e30));
}

// Entry distances of the two child boxes; `hit` says which the ray enters within [tmin, tmax].
// The far slab is widened by a few ulps (Ize's robust traversal) so a box is never missed by
// rounding where Embree would enter it. (A separate flag, not a sentinel distance: with tmax = inf
// a sentinel would count as entered, and lavapipe cuts loops off after 65535 iterations.)
vec2 child_boxes(GpuBvhNode n, vec3 org, vec3 idir, float tmin, float tmax, out bvec2 hit) {
  const float widen = 1.0000004;
  vec2 tx0 = (vec2(n.c0_xy.x, n.c0_xy.y) - org.x) * idir.x;
  vec2 ty0 = (vec2(n.c0_xy.z, n.c0_xy.w) - org.y) * idir.y;
  vec2 tz0 = (vec2(n.z.x, n.z.y) - org.z) * idir.z;
  vec2 tx1 = (vec2(n.c1_xy.x, n.c1_xy.y) - org.x) * idir.x;
  vec2 ty1 = (vec2(n.c1_xy.z, n.c1_xy.w) - org.y) * idir.y;
  vec2 tz1 = (vec2(n.z.z, n.z.w) - org.z) * idir.z;
  float near0 = max(max(min(tx0.x, tx0.y), min(ty0.x, ty0.y)), max(min(tz0.x, tz0.y), tmin));
  float far0 = min(min(max(tx0.x, tx0.y), max(ty0.x, ty0.y)), min(max(tz0.x, tz0.y), tmax)) * widen;
  float near1 = max(max(min(tx1.x, tx1.y), min(ty1.x, ty1.y)), max(min(tz1.x, tz1.y), tmin));
  float far1 = min(min(max(tx1.x, tx1.y), max(ty1.x, ty1.y)), min(max(tz1.x, tz1.y), tmax)) * widen;
  hit = bvec2(near0 <= far0, near1 <= far1);
  return vec2(near0, near1);
}

// A ray in the watertight triangle test's frame (Woop, Benthin and Wald, "Watertight
// Ray/Triangle Intersection", JCGT 2013): kz is the axis the ray runs along most, and the shear
// (Sx, Sy, Sz) takes the ray onto it, so that a triangle's corners become 2D points around the ray.
struct RayFrame {
  uvec3 k;     // kx, ky, kz
  vec3 shear;  // Sx, Sy, Sz
};

RayFrame ray_frame(vec3 dir) {
  vec3 a = abs(dir);
  uint kz = a.x >= a.y ? (a.x >= a.z ? 0u : 2u) : (a.y >= a.z ? 1u : 2u);
  uint kx = (kz + 1u) % 3u, ky = (kx + 1u) % 3u;
  if (dir[kz] < 0.0) {  // keep the winding, so the edge functions' signs keep their meaning
    uint swap = kx;
    kx = ky;
    ky = swap;
  }
  RayFrame f;
  f.k = uvec3(kx, ky, kz);
  f.shear = vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
  return f;
}

// A corner relative to the ray's origin in the ray's frame: (x, y) across the ray, z along it, in
// one fixed sequence of operations: the same bits for a corner whichever triangle reads it.
vec3 sheared_corner(vec3 corner, vec3 org, RayFrame f) {
  vec3 p = corner - org;
  precise float x = p[f.k.x] - f.shear.x * p[f.k.z];
  precise float y = p[f.k.y] - f.shear.y * p[f.k.z];
  return vec3(x, y, f.shear.z * p[f.k.z]);
}

// Both sides, watertight: two triangles that share an edge compute that edge's function from the
// same two sheared corners, one the exact negation of the other (`precise`: no fused multiply-add
// may round one product and not the other), so no ray passes between them, nor through a corner
// that a closed fan of triangles shares. Returns t in [tmin, tmax] or -1; u, v as Embree's (the
// weights of v1 and v2).
float hit_triangle(GpuTriangle tri, vec3 org, RayFrame f, float tmin, float tmax, out float u, out float v) {
  u = 0.0;
  v = 0.0;
  vec3 a = sheared_corner(tri.v0.xyz, org, f);
  vec3 b = sheared_corner(tri.v1.xyz, org, f);
  vec3 c = sheared_corner(tri.v2.xyz, org, f);
  precise float e0 = c.x * b.y - c.y * b.x;  // edge b-c: v0's weight
  precise float e1 = a.x * c.y - a.y * c.x;  // edge c-a: v1's weight
  precise float e2 = b.x * a.y - b.y * a.x;  // edge a-b: v2's weight
  if ((e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0)) return -1.0;
  float det = e0 + e1 + e2;
  if (det == 0.0) return -1.0;
  float inv = 1.0 / det;
  float t = (e0 * a.z + e1 * b.z + e2 * c.z) * inv;
  if (!(t >= tmin && t <= tmax)) return -1.0;
  u = e1 * inv;
  v = e2 * inv;
  return t;
}

// Closest hit (any_hit false) or the first hit found (any_hit true) along org + t dir, t in
// [tmin, tmax]. Returns the triangle slot in `tris` (or GPU_NO_ROOT) and fills t, u, v.
uint traverse(uint root, vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out float t_hit, out float bu,
              out float bv) {
  uint found = GPU_NO_ROOT;
  t_hit = -1.0;
  bu = 0.0;
  bv = 0.0;
  if (root == GPU_NO_ROOT) return found;
  vec3 idir = safe_inverse(dir);
  RayFrame frame = ray_frame(dir);
  uint stack[GPU_STACK];
  int sp = 0;
  uint ref = root;
  while (true) {
    if ((ref & GPU_LEAF_BIT) != 0u) {
      uint first = ref & GPU_LEAF_FIRST_MASK;
      uint count = ((ref >> GPU_LEAF_COUNT_SHIFT) & 15u) + 1u;
      for (uint i = first; i < first + count; ++i) {
        GpuTriangle tri = tris[i];
        float u, v;
        float t = hit_triangle(tri, org, frame, tmin, tmax, u, v);
        if (t < 0.0) continue;
        uint slot = floatBitsToUint(tri.v1.w);
        if (slot != 0u && !alpha_keeps(slot, u, v)) continue;
        found = i;
        t_hit = t;
        bu = u;
        bv = v;
        if (any_hit) return found;
        tmax = t;
      }
    } else {
      GpuBvhNode n = nodes[ref];
      bvec2 hit;
      vec2 near = child_boxes(n, org, idir, tmin, tmax, hit);
      bool hit0 = hit.x, hit1 = hit.y;
      if (hit0 && hit1) {
        bool first0 = near.x <= near.y;
        ref = first0 ? n.children.x : n.children.y;
        if (sp < GPU_STACK) stack[sp++] = first0 ? n.children.y : n.children.x;
        continue;
      }
      if (hit0 || hit1) {
        ref = hit0 ? n.children.x : n.children.y;
        continue;
      }
    }
    if (sp == 0) break;
    ref = stack[--sp];
  }
  return found;
}
