#include "bake/vulkan/bounce.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "io/results/ddgi_result.h"
#include "kernels/sh.h"
#include "kernels/shaders/bounce_pass_spv.h"
#include "kernels/shaders/bounce_weights_spv.h"
#include "kernels/shaders/gpu_types.h"

namespace gibake {
namespace {

static_assert(kIrradianceTexels * kIrradianceTexels == GPU_IRRADIANCE_TEXELS, "irradiance tile");
static_assert(GPU_BOUNCE_PASS_GROUP >= GPU_IRRADIANCE_TEXELS + kernels::kMaxShCoefficients * 3,
              "one pass invocation per irradiance texel and per SH value");

constexpr uint64_t kIrrValues = GPU_IRRADIANCE_TEXELS * 3;

uint32_t float_bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

// A run of whole probes whose hits sit in the hit buffer together.
struct Chunk {
  int32_t first_probe = 0, end_probe = 0;
  uint64_t first_hit = 0, hits = 0;
};

// The buffers, pipelines and dispatch lists of one bounce run.
class BounceRun {
 public:
  BounceRun(vk::Context& vk, const BounceInputs& in) : vk_(vk), in_(in) {}

  Status setup(const GpuBounceOptions& options, GpuBounceStats& stats);
  Status upload_hits(const Chunk& c);
  std::vector<vk::Dispatch> weight_dispatches(const Chunk& c) const;
  std::vector<vk::Dispatch> pass_dispatches(const Chunk& c, int pass) const;
  Status passes(GpuBounceStats& stats);
  Status upload_irradiance(const std::vector<float>& irradiance);
  Status download(std::vector<float>& sh, std::vector<float>& irradiance);
  Status weights(std::vector<kernels::ProbeWeights>& out);

 private:
  void plan(uint64_t chunk_hits);
  uint64_t bytes_needed() const;
  Status check_fits(uint64_t limit) const;
  Status create_buffers();
  Status upload_resident();
  Status run(const std::vector<vk::Dispatch>& d, size_t weight_count, GpuBounceStats& stats);
  const vk::Buffer* sh_of(int pass) const { return pass == 0 ? &sh_base_ : (pass % 2 ? &sh_a_ : &sh_b_); }
  // Probes (workgroups) one pass dispatch takes: the device's maxComputeWorkGroupCount[0].
  uint32_t max_groups() const { return std::min<uint32_t>(vk_.limits().group_count[0], INT32_MAX); }

  vk::Context& vk_;
  const BounceInputs& in_;
  int32_t probe_count_ = 0;
  uint32_t values_ = 0;          // SH values per probe
  std::vector<uint64_t> first_;  // per probe: its first hit, flattened probe after probe
  std::vector<Chunk> chunks_;
  uint64_t capacity_ = 0;  // hits the hit buffer holds
  uint32_t windows_ = 1;   // windows of GPU_RAY_WINDOW hits the probe with the most takes
  gpu::BouncePush push_{};
  vk::Buffer hits_, weights_, probes_, depth_, irr_dirs_, sh_base_, sh_a_, sh_b_, irr_, carry_;
  vk::Pipeline weights_pipe_, pass_pipe_;
};

// Greedy chunks of whole probes within `chunk_hits` (a larger probe gets a chunk of its own).
void BounceRun::plan(uint64_t chunk_hits) {
  const auto& hits = *in_.hits;
  probe_count_ = static_cast<int32_t>(hits.size());
  first_.assign(size_t(probe_count_) + 1, 0);
  uint64_t most = 0;
  for (int32_t p = 0; p < probe_count_; ++p) {
    first_[p + 1] = first_[p] + hits[p].size();
    most = std::max<uint64_t>(most, hits[p].size());
  }
  windows_ = uint32_t(std::max<uint64_t>(1, (most + GPU_RAY_WINDOW - 1) / GPU_RAY_WINDOW));
  chunk_hits = std::clamp<uint64_t>(chunk_hits, 1, uint64_t(1) << 31);
  for (int32_t p = 0; p < probe_count_;) {
    Chunk c;
    c.first_probe = p;
    c.first_hit = first_[p];
    while (p < probe_count_ && (p == c.first_probe || first_[p + 1] - c.first_hit <= chunk_hits)) ++p;
    c.end_probe = p;
    c.hits = first_[p] - c.first_hit;
    capacity_ = std::max(capacity_, c.hits);
    chunks_.push_back(c);
  }
  capacity_ = std::max<uint64_t>(capacity_, 1);
}

uint64_t BounceRun::bytes_needed() const {
  const uint64_t n = uint64_t(std::max(probe_count_, 1));
  const uint64_t tile = uint64_t(in_.volume.depth_res + 2) * (in_.volume.depth_res + 2) * 8;
  return capacity_ * (sizeof(gpu::GpuBounceHit) + sizeof(gpu::GpuProbeWeights)) +
         n * (sizeof(gpu::GpuBounceProbe) + tile + 3 * values_ * 4 + kIrrValues * 4) + GPU_IRRADIANCE_TEXELS * 16;
}

// Before anything is allocated: the per-probe data and one chunk within `limit`, every buffer
// within the device's largest storage buffer.
Status BounceRun::check_fits(uint64_t limit) const {
  const uint64_t need = bytes_needed();
  const uint64_t largest =
      std::max(capacity_ * sizeof(gpu::GpuProbeWeights),
               uint64_t(std::max(probe_count_, 1)) * (in_.volume.depth_res + 2) * (in_.volume.depth_res + 2) * 8);
  if (largest <= vk_.max_buffer_bytes() && limit == vk_.device_memory())
    return vk_.check_device_memory(need, 0, "the bounce passes' per-probe data and one chunk of hits",
                                   "fewer probes lower it (--probe-spacing, --probe-budget, --quality draft); "
                                   "--gather path or --backend cpu");
  if (need <= limit && largest <= vk_.max_buffer_bytes()) return Status::ok();
  return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                       "bounce passes need " + std::to_string(need) + " bytes of device memory (largest buffer " +
                           std::to_string(largest) + "); " + vk_.device().name + " allows " + std::to_string(limit) +
                           " (buffers up to " + std::to_string(vk_.max_buffer_bytes()) + ")");
}

Status BounceRun::create_buffers() {
  const uint64_t n = uint64_t(std::max(probe_count_, 1));
  const uint64_t tile_floats = uint64_t(in_.volume.depth_res + 2) * (in_.volume.depth_res + 2) * 2;
  GIBAKE_TRY(vk_.create_buffer(capacity_ * sizeof(gpu::GpuBounceHit), hits_, "bounce hits"));
  GIBAKE_TRY(vk_.create_buffer(capacity_ * sizeof(gpu::GpuProbeWeights), weights_, "bounce probe weights"));
  GIBAKE_TRY(vk_.create_buffer(n * sizeof(gpu::GpuBounceProbe), probes_, "bounce probe table"));
  GIBAKE_TRY(vk_.create_buffer(n * tile_floats * 4, depth_, "bounce depth tiles"));
  GIBAKE_TRY(vk_.create_buffer(GPU_IRRADIANCE_TEXELS * 16, irr_dirs_, "irradiance texel directions"));
  GIBAKE_TRY(vk_.create_buffer(n * values_ * 4, sh_base_, "bounce pass-0 SH"));
  GIBAKE_TRY(vk_.create_buffer(n * values_ * 4, sh_a_, "bounce SH"));
  GIBAKE_TRY(vk_.create_buffer(n * values_ * 4, sh_b_, "bounce SH"));
  GIBAKE_TRY(vk_.create_buffer(n * kIrrValues * 4, irr_, "bounce irradiance texels"));
  // A probe of more hits than a window carries its sums to the next: a vec4 per pass invocation of
  // each workgroup of a dispatch.
  const uint64_t carried = windows_ > 1 ? std::min<uint64_t>(n, max_groups()) * GPU_BOUNCE_PASS_GROUP * 16 : 16;
  GIBAKE_TRY(vk_.create_buffer(carried, carry_, "bounce sums between windows"));
  GIBAKE_TRY(vk_.create_pipeline(shaders::bounce_weights_spv, sizeof(shaders::bounce_weights_spv) / 4, 4,
                                 sizeof(gpu::BouncePush), weights_pipe_, "bounce_weights"));
  // bounce_pass.comp's shared tiles: s_dir, s_rad (vec4) and s_basis (9 floats) per invocation.
  const uint32_t shared = GPU_BOUNCE_PASS_GROUP * (16 + 16 + 9 * 4);
  return vk_.create_pipeline({shaders::bounce_pass_spv, sizeof(shaders::bounce_pass_spv) / 4, 9,
                              sizeof(gpu::BouncePush), "bounce_pass", shared},
                             pass_pipe_);
}

Status BounceRun::setup(const GpuBounceOptions& options, GpuBounceStats& stats) {
  if (!in_.volume.depth_tiles || !in_.positions || !in_.hits || !in_.sh0 || !in_.probe_rays || !in_.texel_dirs)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "bounce passes need depth tiles and positions");
  if (in_.hits->size() >= (size_t(1) << 24))  // hits name their probe as a float
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "bounce passes: more than 2^24 probes");
  values_ = uint32_t(kernels::sh_coefficient_count(in_.sh_order) * 3);
  // A chunk's weights must fit one storage buffer (maxStorageBufferRange is 128 MiB on some devices).
  plan(std::min<uint64_t>(options.chunk_hits, vk_.max_buffer_bytes() / sizeof(gpu::GpuProbeWeights)));
  stats.chunks = uint32_t(chunks_.size());
  stats.device_bytes = bytes_needed();
  GIBAKE_TRY(check_fits(options.memory_limit ? options.memory_limit : vk_.device_memory()));
  GIBAKE_TRY(create_buffers());
  const kernels::DdgiVolumeView& v = in_.volume;
  push_.grid_min = {v.grid_min[0], v.grid_min[1], v.grid_min[2], v.params[0]};
  push_.spacing = {v.spacing[0], v.spacing[1], v.spacing[2], v.params[1]};
  push_.counts = {uint32_t(v.counts[0]), uint32_t(v.counts[1]), uint32_t(v.counts[2]), uint32_t(v.depth_res)};
  // The CPU's constants, computed as the CPU computes them (shade_indirect, sh_irradiance's kA).
  push_.params = {in_.energy_conservation / kernels::kPi, kernels::kPi, 2.f * kernels::kPi / 3.f, kernels::kPi / 4.f};
  return upload_resident();
}

// The probe table (first hits relative to their chunk), depth tiles, pass-0 SH and texels.
Status BounceRun::upload_resident() {
  std::vector<gpu::GpuBounceProbe> table(size_t(std::max(probe_count_, 1)));
  for (const Chunk& c : chunks_)
    for (int32_t p = c.first_probe; p < c.end_probe; ++p) {
      const uint64_t n = first_[p + 1] - first_[p];
      const float* pos = in_.positions + size_t(p) * 3;
      const float* off = in_.volume.offsets ? in_.volume.offsets + size_t(p) * 3 : nullptr;
      const bool inactive = in_.volume.inactive && in_.volume.inactive[p];
      // integrate_radiance's norm (double, rounded once) and run_bounce_passes' scale, bit for bit.
      const float norm = n > 0 ? static_cast<float>(4.0 * 3.14159265358979323846 / int(n)) : 0.f;
      const float scale = in_.probe_rays[p] == 0 ? 0.f : float(n) / float(in_.probe_rays[p]);
      table[p].position = {pos[0], pos[1], pos[2], inactive ? 1.f : 0.f};
      table[p].offset = {off ? off[0] : 0.f, off ? off[1] : 0.f, off ? off[2] : 0.f, 0.f};
      table[p].range = {uint32_t(first_[p] - c.first_hit), uint32_t(n), float_bits(norm), float_bits(scale)};
    }
  GIBAKE_TRY(vk_.upload(probes_, table.data(), table.size() * sizeof(table[0])));
  if (probe_count_ == 0) return Status::ok();
  const uint64_t tile_bytes = uint64_t(in_.volume.depth_res + 2) * (in_.volume.depth_res + 2) * 8;
  GIBAKE_TRY(vk_.upload(depth_, in_.volume.depth_tiles, uint64_t(probe_count_) * tile_bytes));
  std::vector<gpu::vec4> dirs(GPU_IRRADIANCE_TEXELS);
  for (size_t i = 0; i < dirs.size(); ++i)
    dirs[i] = {in_.texel_dirs[i * 3], in_.texel_dirs[i * 3 + 1], in_.texel_dirs[i * 3 + 2], 0.f};
  GIBAKE_TRY(vk_.upload(irr_dirs_, dirs.data(), dirs.size() * sizeof(dirs[0])));
  return vk_.upload(sh_base_, in_.sh0->data(), uint64_t(probe_count_) * values_ * 4);
}

Status BounceRun::upload_hits(const Chunk& c) {
  if (c.hits == 0) return Status::ok();
  std::vector<gpu::GpuBounceHit> flat(c.hits);
  const auto& hits = *in_.hits;
  for (int32_t p = c.first_probe; p < c.end_probe; ++p) {
    gpu::GpuBounceHit* out = flat.data() + (first_[p] - c.first_hit);
    for (const BounceHit& h : hits[p]) {
      *out++ = {{h.dir_t[0], h.dir_t[1], h.dir_t[2], h.dir_t[3]},
                {h.normal[0], h.normal[1], h.normal[2], float(p)},
                {h.albedo[0], h.albedo[1], h.albedo[2], 0.f}};
    }
  }
  return vk_.upload(hits_, flat.data(), flat.size() * sizeof(flat[0]));
}

std::vector<vk::Dispatch> BounceRun::weight_dispatches(const Chunk& c) const {
  std::vector<vk::Dispatch> out;
  const uint64_t per = uint64_t(max_groups()) * GPU_BOUNCE_WEIGHTS_GROUP;
  for (uint64_t at = 0; at < c.hits; at += per) {
    gpu::BouncePush push = push_;
    const uint64_t n = std::min(per, c.hits - at);
    push.range = {uint32_t(at), uint32_t(n), 0u, 0u};
    vk::Dispatch d;
    d.pipeline = &weights_pipe_;
    d.buffers = {&hits_, &probes_, &depth_, &weights_};
    d.push = vk::push_bytes(push);
    d.flat_groups = uint32_t((n + GPU_BOUNCE_WEIGHTS_GROUP - 1) / GPU_BOUNCE_WEIGHTS_GROUP);
    out.push_back(d);
  }
  return out;
}

// Pass `pass` (1..bounces) over the chunk's probes: reads pass-1's SH, writes pass's.
std::vector<vk::Dispatch> BounceRun::pass_dispatches(const Chunk& c, int pass) const {
  std::vector<vk::Dispatch> out;
  const uint32_t last = pass == in_.bounces ? 1u : 0u;
  // 64-bit steps: a device's group limit can be INT32_MAX, which a later chunk's first probe plus
  // one step would overflow in 32 bits.
  for (int64_t p = c.first_probe; p < c.end_probe; p += max_groups()) {
    const uint32_t n = uint32_t(std::min<int64_t>(max_groups(), c.end_probe - p));
    for (uint32_t w = 0; w < windows_; ++w) {  // each window of the probes' hits in turn
      gpu::BouncePush push = push_;
      push.range = {uint32_t(p), n, values_ / 3u, last};
      push.window = {w * GPU_RAY_WINDOW, GPU_RAY_WINDOW, 0u, 0u};
      vk::Dispatch d;
      d.pipeline = &pass_pipe_;
      d.buffers = {&hits_,  &weights_, &probes_, &irr_dirs_, &sh_base_, sh_of(pass - 1), sh_of(pass),
                   &irr_,   &carry_};
      d.push = vk::push_bytes(push);
      d.groups[0] = n;
      out.push_back(d);
    }
  }
  return out;
}

// One submission; the first `weight_count` dispatches are weights, the rest passes.
Status BounceRun::run(const std::vector<vk::Dispatch>& d, size_t weight_count, GpuBounceStats& stats) {
  if (d.empty()) return Status::ok();
  std::vector<double> seconds;
  GIBAKE_TRY(vk_.run(d, &seconds));
  ++stats.submissions;
  for (size_t i = 0; i < seconds.size(); ++i)
    (i < weight_count ? stats.weights_seconds : stats.pass_seconds) += seconds[i];
  return Status::ok();
}

// Everything resident: one upload of the hits and one submission for the weights and every pass.
// Otherwise, per pass and chunk: the chunk's hits, their weights again, the pass over its probes.
Status BounceRun::passes(GpuBounceStats& stats) {
  if (probe_count_ == 0) return Status::ok();
  if (chunks_.size() == 1) {
    GIBAKE_TRY(upload_hits(chunks_[0]));
    std::vector<vk::Dispatch> all = weight_dispatches(chunks_[0]);
    const size_t weight_count = all.size();
    for (int pass = 1; pass <= in_.bounces; ++pass)
      for (vk::Dispatch& d : pass_dispatches(chunks_[0], pass)) all.push_back(std::move(d));
    return run(all, weight_count, stats);
  }
  for (int pass = 1; pass <= in_.bounces; ++pass)
    for (const Chunk& c : chunks_) {
      GIBAKE_TRY(upload_hits(c));
      std::vector<vk::Dispatch> d = weight_dispatches(c);
      const size_t weight_count = d.size();
      for (vk::Dispatch& x : pass_dispatches(c, pass)) d.push_back(std::move(x));
      GIBAKE_TRY(run(d, weight_count, stats));
    }
  return Status::ok();
}

Status BounceRun::upload_irradiance(const std::vector<float>& irradiance) {
  if (probe_count_ == 0) return Status::ok();
  if (irradiance.size() != size_t(probe_count_) * kIrrValues)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "bounce passes: irradiance texels size mismatch");
  return vk_.upload(irr_, irradiance.data(), irradiance.size() * 4);
}

Status BounceRun::download(std::vector<float>& sh, std::vector<float>& irradiance) {
  sh.resize(size_t(probe_count_) * values_);
  if (probe_count_ == 0) return Status::ok();
  GIBAKE_TRY(vk_.download(*sh_of(in_.bounces), sh.data(), sh.size() * 4));
  return vk_.download(irr_, irradiance.data(), uint64_t(probe_count_) * kIrrValues * 4);
}

Status BounceRun::weights(std::vector<kernels::ProbeWeights>& out) {
  out.assign(first_.back(), kernels::ProbeWeights{});
  GpuBounceStats stats;
  for (const Chunk& c : chunks_) {
    if (c.hits == 0) continue;
    GIBAKE_TRY(upload_hits(c));
    GIBAKE_TRY(run(weight_dispatches(c), SIZE_MAX, stats));
    std::vector<gpu::GpuProbeWeights> w(c.hits);
    GIBAKE_TRY(vk_.download(weights_, w.data(), w.size() * sizeof(w[0])));
    for (uint64_t i = 0; i < c.hits; ++i) {
      kernels::ProbeWeights& o = out[c.first_hit + i];
      const uint32_t probes[8] = {w[i].probe_lo.x, w[i].probe_lo.y, w[i].probe_lo.z, w[i].probe_lo.w,
                                  w[i].probe_hi.x, w[i].probe_hi.y, w[i].probe_hi.z, w[i].probe_hi.w};
      const float weights[8] = {w[i].weight_lo.x, w[i].weight_lo.y, w[i].weight_lo.z, w[i].weight_lo.w,
                                w[i].weight_hi.x, w[i].weight_hi.y, w[i].weight_hi.z, w[i].weight_hi.w};
      for (o.count = 0; o.count < 8 && probes[o.count] != GPU_BOUNCE_NO_PROBE; ++o.count) {
        o.probe[o.count] = int32_t(probes[o.count]);
        o.weight[o.count] = weights[o.count];
      }
    }
  }
  return Status::ok();
}

}  // namespace

Status run_bounce_passes_gpu(vk::Context& vk, const BounceInputs& in, std::vector<float>& sh,
                             std::vector<float>& irradiance, GpuBounceStats& stats, const GpuBounceOptions& options) {
  if (in.bounces <= 0) {  // as run_bounce_passes: pass 0's SH, texels untouched
    sh = *in.sh0;
    return Status::ok();
  }
  BounceRun r(vk, in);
  GIBAKE_TRY(r.setup(options, stats));
  GIBAKE_TRY(r.upload_irradiance(irradiance));
  GIBAKE_TRY(r.passes(stats));
  return r.download(sh, irradiance);
}

Status gpu_bounce_weights(vk::Context& vk, const BounceInputs& in, std::vector<kernels::ProbeWeights>& out,
                          const GpuBounceOptions& options) {
  BounceRun r(vk, in);
  GpuBounceStats stats;
  GIBAKE_TRY(r.setup(options, stats));
  return r.weights(out);
}

}  // namespace gibake
