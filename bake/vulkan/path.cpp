#include "bake/vulkan/path.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "bake/scene/material.h"
#include "bake/vulkan/pipelines.h"
#include "io/timer.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"

namespace gibake {
using kernels::float3;

namespace {

struct Packed {
  std::vector<gpu::GpuVertex> verts;
  std::vector<gpu::GpuShadeTri> tris;
  std::vector<gpu::GpuShadeMaterial> mats;
  std::vector<float> emit_cdf, sky, sky_cdf;
  std::vector<gpu::GpuLight> lights;
  std::vector<uint32_t> emit_tris;
  bool glass = false;  // a triangle's material transmits (PreparedScene::has_transmission)
};

uint32_t texture_index(const Scene& scene, const TextureRef& r) {
  return r.texture >= 0 && size_t(r.texture) < scene.textures.size() ? uint32_t(r.texture) : GPU_NO_TEXTURE;
}

void pack_materials(const Scene& scene, Packed& pk) {
  for (size_t i = 0; i <= scene.materials.size(); ++i) {
    static const Material kDefault{};
    const Material& m = i < scene.materials.size() ? scene.materials[i] : kDefault;
    gpu::GpuShadeMaterial g{};
    const TextureRef &b = m.base_color_texture, &e = m.emissive_texture;
    g.base_color = {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]};
    g.base_xform = {b.offset[0], b.offset[1], b.scale[0], b.scale[1]};
    g.emissive = {m.emissive[0], m.emissive[1], m.emissive[2], m.is_emissive() ? m.emissive_strength : 0.f};
    g.emit_xform = {e.offset[0], e.offset[1], e.scale[0], e.scale[1]};
    g.rot = {b.rotation, b.has_transform ? 1.f : 0.f, e.rotation, e.has_transform ? 1.f : 0.f};
    uint32_t transmission;  // float bits; 0 (0.f) for opaque materials
    std::memcpy(&transmission, &m.transmission, 4);
    g.tex = {texture_index(scene, b), texture_index(scene, e), m.double_sided ? 1u : 0u, transmission};
    const TextureRef& tr = m.transmission_texture;
    uint32_t rotation;
    std::memcpy(&rotation, &tr.rotation, 4);
    g.trans_xform = {tr.offset[0], tr.offset[1], tr.scale[0], tr.scale[1]};
    g.trans_tex = {m.transmission > 0.f ? texture_index(scene, tr) : GPU_NO_TEXTURE, rotation,
                   tr.has_transform ? 1u : 0u, 0u};
    pk.mats.push_back(g);
  }
}

void pack_geometry(const GpuPathSetup& s, const std::vector<uint32_t>& alpha_slot, Packed& pk) {
  const Scene& scene = *s.scene;
  const size_t nv = scene.vertex_count();
  const bool uvs = scene.uvs.size() >= nv * 2, normals = scene.normals.size() >= nv * 3,
             colors = scene.colors.size() >= nv * 4;
  // Element by element, side by side in the caller's arena: on one thread this packing of a large
  // scene would delay the trace's set-up.
  pk.verts.resize(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t v = range.begin(); v < range.end(); ++v) {
      const float* p = &scene.positions[v * 3];
      gpu::GpuVertex& g = pk.verts[v];
      g.pos_u = {p[0], p[1], p[2], uvs ? scene.uvs[v * 2] : 0.f};
      g.normal_v = {normals ? scene.normals[v * 3] : 0.f, normals ? scene.normals[v * 3 + 1] : 0.f,
                    normals ? scene.normals[v * 3 + 2] : 0.f, uvs ? scene.uvs[v * 2 + 1] : 0.f};
      g.color = colors ? gpu::vec4{scene.colors[v * 4], scene.colors[v * 4 + 1], scene.colors[v * 4 + 2],
                                   scene.colors[v * 4 + 3]}
                       : gpu::vec4{1.f, 1.f, 1.f, 1.f};
    }
  });
  const uint32_t default_material = uint32_t(scene.materials.size());
  pk.tris.resize(scene.triangle_count());
  std::atomic<bool> glass{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pk.tris.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    bool any_glass = false;
    for (size_t t = range.begin(); t < range.end(); ++t) {
      const int32_t m = t < scene.tri_material.size() ? scene.tri_material[t] : -1;
      const bool known = m >= 0 && size_t(m) < scene.materials.size();
      any_glass = any_glass || (known && scene.materials[size_t(m)].transmission > 0.f);
      float slot;
      std::memcpy(&slot, &alpha_slot[t], 4);
      pk.tris[t] = {
          {scene.indices[t * 3], scene.indices[t * 3 + 1], scene.indices[t * 3 + 2],
           known ? uint32_t(m) : default_material},
          {s.lod ? s.lod->uv_per_metre(uint32_t(t)) : 0.f, s.emitters ? s.emitters->pdf_area(uint32_t(t)) : 0.f, slot,
           s.lod ? s.lod->max_uv_width(uint32_t(t)) : 0.f}};
    }
    if (any_glass) glass.store(true, std::memory_order_relaxed);
  });
  pk.glass = glass.load();
}

void pack_lights_sky(const GpuPathSetup& s, Packed& pk) {
  for (const kernels::ShadeLight& l : *s.lights) {
    gpu::GpuLight g;
    std::memcpy(&g, &l, sizeof(g));
    pk.lights.push_back(g);
  }
  if (s.emitters && !s.emitters->empty()) {
    pk.emit_tris = s.emitters->triangles();
    for (double c : s.emitters->cdf()) pk.emit_cdf.push_back(float(c));
  }
  if (s.sky && !s.sky->rgb.empty()) pk.sky = s.sky->rgb;
  if (s.probe_lights && s.sky && s.sky->sampled() && !pk.sky.empty()) {  // Sky::row_cdf, then col_cdf
    pk.sky_cdf = s.sky->row_cdf;
    pk.sky_cdf.insert(pk.sky_cdf.end(), s.sky->col_cdf.begin(), s.sky->col_cdf.end());
  }
}

}  // namespace

static_assert(sizeof(gpu::GpuLight) == sizeof(kernels::ShadeLight), "GpuLight mirrors ShadeLight");

GpuPathTracer::~GpuPathTracer() = default;

uint32_t path_batch_rays(const vk::DeviceInfo& device, uint64_t device_memory) {
  constexpr uint32_t kSmall = 1u << 19, kLarge = 1u << 23;
  if (!device.is_gpu()) return kSmall;
  // At most 1/32 of the device's memory for a batch's buffers.
  uint32_t rays = kLarge;
  while (rays > kSmall && uint64_t(rays) * kPathBatchBytesPerRay * 32 > device_memory) rays >>= 1;
  return rays;
}

Status GpuPathTracer::create(GpuTracer& bvh, const GpuPathSetup& s, std::unique_ptr<GpuPathTracer>& out,
                             uint32_t batch_rays) {
  std::unique_ptr<GpuPathTracer> t(new GpuPathTracer(bvh));
  vk::Context& vk = bvh.vk_;
  // Scene triangle -> alpha slot, from the BVH's triangles (the same records the traversal reads).
  std::vector<uint32_t> slot(s.scene->triangle_count(), 0);
  for (size_t i = 0; i < bvh.record_triangle_.size(); ++i)
    if (bvh.record_triangle_[i] < slot.size()) slot[bvh.record_triangle_[i]] = bvh.record_alpha_[i];
  auto t0 = Clock::now();
  if (s.textures && s.textures->lod == s.lod) {
    t->textures_ = s.textures;
  } else {
    GIBAKE_TRY(create_gpu_texture_pool(vk, *s.scene, *s.lod, t->own_textures_));
    t->textures_ = t->own_textures_.get();
  }
  const double own_upload_s = t->own_textures_ ? t->own_textures_->upload_seconds : 0.0;
  Packed pk;
  pack_materials(*s.scene, pk);
  pack_geometry(s, slot, pk);
  pack_lights_sky(s, pk);
  t->max_batch_ = std::max<uint32_t>(64, batch_rays ? batch_rays : path_batch_rays(vk.device(), vk.device_memory()));
  // Every per-ray buffer of a batch within the device's largest storage buffer.
  const uint64_t widest = std::max({sizeof(gpu::GpuPathRay), sizeof(gpu::GpuPathOut), sizeof(gpu::GpuPathBrief),
                                    sizeof(gpu::GpuRaySample)});
  while (t->max_batch_ > 64 && uint64_t(t->max_batch_) * widest > vk.max_buffer_bytes()) t->max_batch_ /= 2;
  // The shading data is the scene's and cannot shrink; the ray batch halves until the whole fits
  // beside the BVH (the trace then takes more, smaller batches: the same rays, the same bytes).
  const uint64_t fixed = pk.verts.size() * sizeof(gpu::GpuVertex) + pk.tris.size() * sizeof(gpu::GpuShadeTri) +
                         t->textures_->pool_bytes + pk.sky.size() * 4;
  const uint64_t room = vk.device_memory() - std::min(vk.device_memory(), bvh.device_bytes());
  while (t->max_batch_ > 64 && fixed + uint64_t(t->max_batch_) * kPathBatchBytesPerRay > room) t->max_batch_ /= 2;
  GIBAKE_TRY(vk.check_device_memory(fixed + uint64_t(t->max_batch_) * kPathBatchBytesPerRay, bvh.device_bytes(),
                                    "the path gather's shading data (vertices, textures with mips) and one ray batch",
                                    "the scene decides it: --backend cpu bakes without the device"));
  t->setup_seconds_[0] = seconds_since(t0) - own_upload_s;
  t0 = Clock::now();
  uint64_t& total = t->device_bytes_;
  if (t->own_textures_) total += t->own_textures_->device_bytes;
  GIBAKE_TRY(vk.create_filled_buffer(pk.verts, t->verts_, "vertices", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.tris, t->shade_tris_, "shading triangles", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.mats, t->shade_mats_, "materials", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.lights, t->lights_, "lights", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.emit_cdf, t->emit_cdf_, "emitter table", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.emit_tris, t->emit_tris_, "emitter triangles", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.sky, t->sky_, "sky map", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.sky_cdf, t->sky_cdf_, "sky map sampling tables", total));
  gpu::GpuPathParams& P = t->params_;
  P.counts = {0u, bvh.root_, uint32_t(pk.lights.size()), uint32_t(pk.emit_tris.size())};
  const bool sky_black = !s.sky || s.sky->is_black();
  P.flags = {s.random_light ? 1u : 0u, uint32_t(std::max(0, s.bounces)), uint32_t(std::max(0, s.roulette_depth)),
             (!pk.emit_tris.empty() || !sky_black) ? 1u : 0u};
  const float3 sc = s.sky ? s.sky->constant : float3{};
  P.sky = {sc.x, sc.y, sc.z, s.sky ? s.sky->scale : 0.f};
  // The probe's light samples (TraceStage::probe_lights): emitters, and the sky map where sampled
  // (half the samples each when both; path_gather.cpp probe_sky_share).
  const bool sky_sampled = !pk.sky_cdf.empty();
  const bool probe_lights = s.probe_lights && !s.probe_feedback && (!pk.emit_tris.empty() || sky_sampled);
  const float sky_share = probe_lights && sky_sampled ? (pk.emit_tris.empty() ? 1.f : 0.5f) : 0.f;
  P.sky_map = {pk.sky.empty() ? 0u : uint32_t(s.sky->width), pk.sky.empty() ? 0u : uint32_t(s.sky->height),
               s.probe_feedback ? 1u : 0u, probe_lights ? 1u : 0u};
  P.misc = {s.cone_spread, s.shadow_bias, pk.glass ? 1.f : 0.f, sky_share};
  if (s.lights) t->host_lights_ = *s.lights;
  t->setup_ = s;
  t->sky_map_hash_ = pk.sky.empty() ? 0 : XXH3_64bits(pk.sky.data(), pk.sky.size() * sizeof(float));
  GIBAKE_TRY(vk.create_buffer(sizeof(P), t->params_buf_, "path parameters"));
  // Bound where a trace writes no integration samples (the kernel then never touches it).
  GIBAKE_TRY(vk.create_buffer(sizeof(gpu::GpuRaySample), t->no_samples_, "path samples placeholder"));
  t->setup_seconds_[1] = seconds_since(t0) + own_upload_s;
  t0 = Clock::now();
  GIBAKE_TRY(vk.create_pipeline(pipelines::path(), t->path_));
  GIBAKE_TRY(GpuRayGen::create(vk, t->raygen_));
  if (vk.shader_float64()) GIBAKE_TRY(GpuProbeStatsReducer::create(vk, t->stats_));
  t->setup_seconds_[2] = seconds_since(t0);
  out = std::move(t);
  return Status::ok();
}

bool GpuPathTracer::serves(const GpuPathSetup& o) const {
  const GpuPathSetup& s = setup_;
  const size_t lights = o.lights ? o.lights->size() : 0;
  if (lights != host_lights_.size() ||
      (lights && std::memcmp(o.lights->data(), host_lights_.data(), lights * sizeof(host_lights_[0])) != 0))
    return false;
  return o.scene == s.scene && o.lod == s.lod && o.emitters == s.emitters && o.sky == s.sky &&
         o.textures == s.textures && o.random_light == s.random_light && o.bounces == s.bounces &&
         o.roulette_depth == s.roulette_depth && o.cone_spread == s.cone_spread && o.shadow_bias == s.shadow_bias &&
         o.probe_feedback == s.probe_feedback && o.probe_lights == s.probe_lights;
}

Status GpuPathTracer::reserve_batch(uint64_t rays, bool full_outputs) {
  const uint32_t want = uint32_t(std::min<uint64_t>(max_batch_, std::max<uint64_t>(64, rays)));
  if (want <= batch_ && (!full_outputs || outs_batch_ >= batch_)) return Status::ok();
  vk::Context& vk = bvh_.vk_;
  device_bytes_ -= batch_bytes();
  if (want > batch_) {
    batch_ = 0;
    const uint64_t light = probe_lights() ? want : 1;
    GIBAKE_TRY(vk.create_buffer(uint64_t(want) * sizeof(gpu::GpuPathRay), rays_, "path ray batch"));
    GIBAKE_TRY(vk.create_buffer(uint64_t(want) * sizeof(gpu::GpuPathBrief), briefs_, "path brief batch"));
    GIBAKE_TRY(vk.create_buffer(light * sizeof(gpu::GpuRaySample), light_out_, "probe emitter sample batch"));
    batch_ = want;
  }
  if (full_outputs && outs_batch_ < batch_) {  // as many as a batch holds
    outs_batch_ = 0;
    GIBAKE_TRY(vk.create_buffer(uint64_t(batch_) * sizeof(gpu::GpuPathOut), outs_, "path output batch"));
    outs_batch_ = batch_;
  }
  device_bytes_ += batch_bytes();
  return Status::ok();
}

uint64_t GpuPathTracer::batch_bytes() const {
  const uint64_t light = probe_lights() ? sizeof(gpu::GpuRaySample) : 0;
  return uint64_t(batch_) * (sizeof(gpu::GpuPathRay) + sizeof(gpu::GpuPathBrief) + light) +
         uint64_t(outs_batch_) * sizeof(gpu::GpuPathOut);
}

// Lanes take a probe's rays in blocks sorted by direction (bake/vulkan/raygen.h lane_order): the largest
// power of two up to 256 that divides both the rays per probe and the batch, so that no block
// straddles a probe or a batch (chunks hold whole probes; a batch smaller than max_batch_ holds the
// whole chunk).
Status GpuPathTracer::set_fibonacci(const float* set, uint32_t rays_per_probe) {
  uint32_t block = 256;
  while (block > 1 && (rays_per_probe % block != 0 || max_batch_ % block != 0)) block /= 2;
  return raygen_->set_fibonacci(set, rays_per_probe, block);
}

vk::Dispatch GpuPathTracer::path_dispatch(const PathChunk& c, uint32_t first, uint32_t n) const {
  const bool brief = c.brief && c.samples;
  const gpu::PathPush push{{c.samples ? 1u : 0u, first, brief ? 1u : 0u, raygen_->rays_per_probe()},
                           {c.max_distance, 0.f, 0.f, 0.f}};
  return path_dispatch(push, c.samples, &raygen_->order(), n);
}

vk::Dispatch GpuPathTracer::path_dispatch(const gpu::PathPush& push, const vk::Buffer* samples, const vk::Buffer* order,
                                          uint32_t n) const {
  vk::Dispatch d;
  d.pipeline = &path_;
  d.buffers = {&bvh_.nodes_, &bvh_.tris_,  &bvh_.alpha_tris_, &bvh_.materials_, &bvh_.textures_, &bvh_.texels_,
               &verts_,      &shade_tris_, &shade_mats_,      &textures_->textures, &textures_->levels,
               &textures_->pool, &textures_->srgb, &lights_, &emit_cdf_, &emit_tris_, &sky_, &params_buf_,
               &rays_,       &outs_};
  if (!outs_batch_) d.buffers[19] = &no_samples_;  // the brief route writes no per-ray outputs
  d.buffers.push_back(samples ? samples : &no_samples_);
  d.buffers.push_back(&briefs_);
  d.buffers.push_back(&light_out_);
  d.buffers.push_back(&sky_cdf_);
  d.buffers.push_back(order ? order : &no_samples_);
  d.push = vk::push_bytes(push);
  d.flat_groups = (n + 63) / 64;
  return d;
}

namespace {

void count_path(const kernels::HitRecord& rec, uint32_t shadow, uint32_t bounce, uint32_t back,
                TraceCounters& counters) {
  ++counters.rays;
  counters.shadow_rays += shadow;
  counters.bounce_rays += bounce;
  counters.back_faces += back;
  if (rec.kind() == kernels::kHitFront && (counters.nearest_front < 0.f || rec.dir_t[3] < counters.nearest_front))
    counters.nearest_front = rec.dir_t[3];
}

}  // namespace

kernels::HitRecord path_record(const gpu::GpuPathBrief& b, TraceCounters& counters) {
  kernels::HitRecord rec;
  rec.dir_t[3] = b.radiance_t.w;
  rec.normal_kind[3] = float(b.counts.w);
  rec.radiance0[0] = b.radiance_t.x;
  rec.radiance0[1] = b.radiance_t.y;
  rec.radiance0[2] = b.radiance_t.z;
  count_path(rec, b.counts.x, b.counts.y, b.counts.z, counters);
  return rec;
}

kernels::HitRecord path_record(const gpu::GpuPathOut& o, TraceCounters& counters) {
  kernels::HitRecord rec;
  std::memcpy(rec.dir_t, &o.dir_t, 16);
  std::memcpy(rec.normal_kind, &o.normal_kind, 16);
  rec.radiance0[0] = o.radiance.x;
  rec.radiance0[1] = o.radiance.y;
  rec.radiance0[2] = o.radiance.z;
  rec.albedo[0] = o.albedo.x;
  rec.albedo[1] = o.albedo.y;
  rec.albedo[2] = o.albedo.z;
  count_path(rec, o.counts.x, o.counts.y, o.counts.z, counters);
  return rec;
}

void make_path_rays(const float3& o, const float* dirs, uint32_t count, uint64_t seed, uint32_t probe, uint32_t pass,
                    gpu::GpuPathRay* out) {
  for (uint32_t r = 0; r < count; ++r) {
    const uint64_t key = kernels::rng_hash(seed, probe, pass, r);
    const uint64_t shift = kernels::rng_hash(seed, probe, pass, kernels::kProbeLightShiftRay);
    out[r] = {{o.x, o.y, o.z, 0.f},
              {dirs[r * 3], dirs[r * 3 + 1], dirs[r * 3 + 2], 0.f},
              {uint32_t(key), uint32_t(key >> 32), uint32_t(shift), uint32_t(shift >> 32)}};
  }
}

}  // namespace gibake
