// The file bench_gpu_trace_dump writes and bench_gpu_trace_run reads: a GPU scene (BVH, triangles,
// alpha data; textures as alpha only, all the traversal reads) and a sample of a bake's own rays
// with Embree's answers, so the GPU machine needs neither Embree nor the scene files.
// Layout: magic "GBTR", version 1, then length-prefixed arrays (uint64 count + raw elements).
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "bake/vulkan/device_scene.h"

namespace gibake::bench {

struct TraceDump {
  GpuSceneData scene;
  std::vector<gpu::GpuRay> closest, shadow;
  std::vector<float> closest_t;       // Embree's hit distance per closest ray (-1: miss)
  std::vector<uint8_t> shadow_blocked;  // Embree's answer per shadow ray
  std::string note;                   // how the rays were made (scene, probes, rays, bounces)
};

namespace detail {
template <class T>
bool put(std::FILE* f, const std::vector<T>& v) {
  const uint64_t n = v.size();
  return std::fwrite(&n, 8, 1, f) == 1 && (n == 0 || std::fwrite(v.data(), sizeof(T), n, f) == n);
}
template <class T>
bool get(std::FILE* f, std::vector<T>& v) {
  uint64_t n = 0;
  if (std::fread(&n, 8, 1, f) != 1 || n > (uint64_t(1) << 34) / sizeof(T)) return false;
  v.resize(n);
  return n == 0 || std::fread(v.data(), sizeof(T), n, f) == n;
}
}  // namespace detail

inline bool write_dump(const std::string& path, const TraceDump& d) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const uint32_t head[4] = {0x52544247u, 1u, d.scene.root, d.scene.depth};
  const uint64_t tris = d.scene.scene_triangles;
  const std::vector<char> note(d.note.begin(), d.note.end());
  bool ok = std::fwrite(head, 4, 4, f) == 4 && std::fwrite(&tris, 8, 1, f) == 1;
  ok = ok && detail::put(f, d.scene.nodes) && detail::put(f, d.scene.triangles) &&
       detail::put(f, d.scene.alpha_triangles) && detail::put(f, d.scene.materials) &&
       detail::put(f, d.scene.textures);
  std::vector<uint8_t> alpha(d.scene.texels.size());
  for (size_t i = 0; i < alpha.size(); ++i) alpha[i] = uint8_t(d.scene.texels[i] >> 24);
  ok = ok && detail::put(f, alpha) && detail::put(f, d.closest) && detail::put(f, d.shadow) &&
       detail::put(f, d.closest_t) && detail::put(f, d.shadow_blocked) && detail::put(f, note);
  return std::fclose(f) == 0 && ok;
}

inline bool read_dump(const std::string& path, TraceDump& d) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  uint32_t head[4];
  uint64_t tris = 0;
  bool ok = std::fread(head, 4, 4, f) == 4 && head[0] == 0x52544247u && head[1] == 1u && std::fread(&tris, 8, 1, f) == 1;
  d.scene.root = head[2];
  d.scene.depth = head[3];
  d.scene.scene_triangles = tris;
  std::vector<uint8_t> alpha;
  std::vector<char> note;
  ok = ok && detail::get(f, d.scene.nodes) && detail::get(f, d.scene.triangles) &&
       detail::get(f, d.scene.alpha_triangles) && detail::get(f, d.scene.materials) &&
       detail::get(f, d.scene.textures) && detail::get(f, alpha) && detail::get(f, d.closest) &&
       detail::get(f, d.shadow) && detail::get(f, d.closest_t) && detail::get(f, d.shadow_blocked) &&
       detail::get(f, note);
  d.scene.texels.resize(alpha.size());
  for (size_t i = 0; i < alpha.size(); ++i) d.scene.texels[i] = uint32_t(alpha[i]) << 24;
  d.note.assign(note.begin(), note.end());
  std::fclose(f);
  return ok;
}

}  // namespace gibake::bench
