// Minimal float3 math for the CPU kernels (plain data, mirrors GLSL vec3 so a compute twin reads alike).
#pragma once
#include <cmath>

namespace gibake::kernels {

struct float3 {
  float x = 0.f, y = 0.f, z = 0.f;
};

inline float3 make_float3(float x, float y, float z) { return float3{x, y, z}; }
inline float3 load3(const float* p) { return float3{p[0], p[1], p[2]}; }
inline void store3(float* p, const float3& v) { p[0] = v.x; p[1] = v.y; p[2] = v.z; }
inline float3 operator+(const float3& a, const float3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline float3 operator-(const float3& a, const float3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline float3 operator-(const float3& a) { return {-a.x, -a.y, -a.z}; }
inline float3 operator*(const float3& a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float3 operator*(float s, const float3& a) { return {a.x * s, a.y * s, a.z * s}; }
inline float3 operator*(const float3& a, const float3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline float3& operator+=(float3& a, const float3& b) { a.x += b.x; a.y += b.y; a.z += b.z; return a; }
inline float dot(const float3& a, const float3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float3 cross(const float3& a, const float3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const float3& a) { return std::sqrt(dot(a, a)); }
inline float3 normalize(const float3& a) {
  const float l = length(a);
  return l > 0.f ? a * (1.f / l) : float3{0.f, 0.f, 0.f};
}
// Relative luminance of linear Rec. 709 RGB, the working space DESIGN.md fixes; every measure of
// "how bright" (errors, weights, stops, image blocks) uses these weights so that they agree.
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
inline float luminance(const float* rgb) { return luminance(rgb[0], rgb[1], rgb[2]); }
inline float luminance(const float3& c) { return luminance(c.x, c.y, c.z); }
inline float saturate(float v) { return v < 0.f ? 0.f : (v > 1.f ? 1.f : v); }
inline float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

constexpr float kPi = 3.14159265358979323846f;

}  // namespace gibake::kernels
