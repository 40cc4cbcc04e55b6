#include "bake/vulkan/path_pipeline.h"

#include <algorithm>
#include <cstring>

#include "io/timer.h"

namespace gibake {

Status GpuPathTracer::reserve_chunks(size_t probes, bool full_outputs) {
  GIBAKE_TRY(raygen_->reserve_probes(probes));
  GIBAKE_TRY(reserve_batch(uint64_t(probes) * raygen_->rays_per_probe(), full_outputs));
  if (stats_) GIBAKE_TRY(stats_->reserve(probes));
  return Status::ok();
}

// A chunk's steps, batch after batch, into one recording.
Status GpuPathTracer::record(const PathChunk& c, vk::Recording& rec, PathRecorded& out) {
  const uint32_t rpp = raygen_->rays_per_probe();
  out = PathRecorded{};
  out.probes = c.probes->size();
  out.rays = uint64_t(out.probes) * rpp;
  out.brief = c.brief && c.samples;
  out.stats = out.brief && c.stats && stats_;
  // Without the device's statistics the host reduces each ray with its light sample (trace()'s rule).
  out.lights = probe_lights() && !out.stats;
  if (out.stats && stats_->capacity() < out.probes)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "statistics buffer not reserved for the chunk");
  if (!out.brief && outs_batch_ < batch_)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "per-ray outputs not reserved for the chunk");
  GIBAKE_TRY(raygen_->record_probes(*c.probes, rec));
  // --target-error's passes: the statistics kernel continues every probe from its state so far.
  const bool resume = out.stats && c.resume;
  if (resume) {
    if (c.resume->size() != out.probes)
      return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "statistics to resume do not match the chunk");
    rec.upload(stats_->buffer(), c.resume->data(), out.probes * sizeof(gpu::GpuProbeStats));
  }
  for (uint64_t first = 0; first < out.rays; first += batch_) {
    const uint32_t n = uint32_t(std::min<uint64_t>(batch_, out.rays - first));
    gpu::GpuPathParams params = params_;
    params.counts.x = n;
    rec.upload(params_buf_, &params, sizeof(params));
    out.batch_rays.push_back(n);
    out.raygen.push_back(rec.dispatch(raygen_->dispatch(rays_, uint32_t(first), n, c.seed)));
    out.path.push_back(rec.dispatch(path_dispatch(c, uint32_t(first), n)));
    // The statistics kernel reduces the briefs (each ray's luminance plus its light sample's) before
    // the next batch overwrites them.
    if (out.stats)
      for (vk::Dispatch& d :
           stats_->dispatch(briefs_, uint32_t(first), n, rpp, probe_lights() ? &light_out_ : nullptr, resume))
        out.reduce.push_back(rec.dispatch(std::move(d)));
    else if (out.brief)
      out.downloads.push_back(rec.download(briefs_, uint64_t(n) * sizeof(gpu::GpuPathBrief)));
    else
      out.downloads.push_back(rec.download(outs_, uint64_t(n) * sizeof(gpu::GpuPathOut)));
    if (out.lights)
      out.light_downloads.push_back(rec.download(light_out_, uint64_t(n) * sizeof(gpu::GpuRaySample)));
  }
  if (out.stats) out.downloads.push_back(rec.download(stats_->buffer(), out.probes * sizeof(gpu::GpuProbeStats)));
  return Status::ok();
}

void GpuPathTracer::collect(const vk::Recording& rec, const PathRecorded& r, PathResult& out, PathTimes* times) const {
  out.outs.resize(r.brief ? 0 : r.rays);
  out.briefs.resize(r.brief && !r.stats ? r.rays : 0);
  out.stats.resize(r.stats ? r.probes : 0);
  out.lights.resize(r.lights ? r.rays : 0);
  if (r.stats) {
    std::memcpy(out.stats.data(), rec.result(r.downloads[0]), r.probes * sizeof(gpu::GpuProbeStats));
  } else {
    uint64_t first = 0;
    for (size_t b = 0; b < r.batch_rays.size(); ++b) {
      const uint32_t n = r.batch_rays[b];
      if (r.brief)
        std::memcpy(&out.briefs[first], rec.result(r.downloads[b]), uint64_t(n) * sizeof(gpu::GpuPathBrief));
      else
        std::memcpy(&out.outs[first], rec.result(r.downloads[b]), uint64_t(n) * sizeof(gpu::GpuPathOut));
      if (r.lights)
        std::memcpy(&out.lights[first], rec.result(r.light_downloads[b]), uint64_t(n) * sizeof(gpu::GpuRaySample));
      first += n;
    }
  }
  if (!times) return;
  const std::vector<double>& s = rec.dispatch_seconds();
  for (size_t i : r.raygen) times->raygen += s[i];
  for (size_t i : r.path) times->path += s[i];
  for (size_t i : r.reduce) times->stats += s[i];
}

namespace {

// One chunk's host side: its recording (staging, results) and what its results are read with.
struct Slot {
  vk::Recording rec;
  std::vector<int32_t> part;
  std::vector<gpu::GpuRayGenProbe> records;
  std::vector<gpu::GpuProbeStats> resume;  // --target-error: the probes' statistics so far
  std::vector<GpuIntegrator::AccumulateProbe> accumulate;
  PathRecorded path;
  IntegrateRecorded integ;
  bool used = false;
};

// How many probes a chunk holds, and every buffer the chunks need reserved before any is in
// flight (nothing grows under a recording); `passes`: --target-error's passes on the device, with
// statistics resumed and integrals accumulated in the probes' slots.
Status reserve_chunks(vk::Context& vk, GpuPathTracer& tracer, GpuIntegrator* integrator,
                      const std::vector<int32_t>& probes, const PathRays& p, const PipelineOptions& options,
                      size_t& chunk, vk::Buffer*& samples, bool& passes) {
  const uint32_t n = p.rays_per_probe;
  GIBAKE_TRY(tracer.set_fibonacci(p.fibonacci, n));
  chunk = std::max<size_t>(1, size_t(options.chunk_rays / n));
  // With the probe's light samples, each ray's follows its probe's rays in the integration buffer.
  const uint64_t per_ray = tracer.probe_lights() ? 2 : 1;
  if (integrator) {
    chunk = std::min<size_t>(chunk, integrator->batch_probes());
    // The chunk's integration samples in one storage buffer of the device's (at least one probe:
    // one that does not fit fails in reserve_samples, naming the limit).
    const uint64_t probe_bytes = uint64_t(n) * per_ray * sizeof(gpu::GpuRaySample);
    chunk = std::max<size_t>(1, std::min<size_t>(chunk, vk.max_buffer_bytes() / probe_bytes));
  }
  chunk = std::min(chunk, probes.size());
  // The brief route (PathChunk::brief with the integrator's samples) writes no per-ray outputs.
  GIBAKE_TRY(tracer.reserve_chunks(chunk, !(p.brief && integrator)));
  samples = nullptr;
  if (integrator) {
    GIBAKE_TRY(integrator->reserve_samples(uint64_t(chunk) * n * per_ray, samples));
    GIBAKE_TRY(integrator->reserve_windows(chunk, uint64_t(n) * per_ray));
  }
  passes = p.resume && integrator && p.stats && tracer.device_stats();
  if (p.resume && !passes)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "device passes need statistics and an integrator");
  if (passes) {
    size_t slots = 0;
    for (int32_t q : probes) slots = std::max(slots, size_t(q - p.slot_base) + 1);
    GIBAKE_TRY(integrator->reserve_accumulators(slots));
  }
  return Status::ok();
}

// Slot `s`'s probes (their ray generation records filled) into its recording: the path kernel's
// batches and the integration (accumulated in the probes' slots under `passes`).
Status record_chunk(GpuPathTracer& tracer, GpuIntegrator* integrator, const PathRays& p, vk::Buffer* samples,
                    bool passes, Slot& s) {
  const uint32_t n = p.rays_per_probe;
  const bool paired = tracer.probe_lights();
  PathChunk c;
  c.probes = &s.records;
  c.seed = p.seed;
  c.samples = samples;
  c.max_distance = p.max_distance;
  c.brief = p.brief;
  c.stats = p.stats;
  if (passes) {
    s.resume.resize(s.part.size());
    s.accumulate.resize(s.part.size());
    for (size_t i = 0; i < s.part.size(); ++i) {
      s.resume[i] = (*p.resume)[size_t(s.part[i])];
      s.accumulate[i] = {uint32_t(s.part[i] - p.slot_base), s.resume[i].counts.x + n};
    }
    c.resume = &s.resume;
  }
  GIBAKE_TRY(tracer.record(c, s.rec, s.path));
  if (passes) return integrator->record_accumulate(s.accumulate, n, s.rec, s.integ, paired);
  if (integrator) return integrator->record_resident(std::vector<uint32_t>(s.part.size(), n), s.rec, s.integ, paired);
  return Status::ok();
}

}  // namespace

Status trace_paths_pipelined(vk::Context& vk, GpuPathTracer& tracer, GpuIntegrator* integrator,
                             const std::vector<int32_t>& probes, const PathRays& p, const ChunkDone& done,
                             const PipelineOptions& options, PipelineTimes& times) {
  const auto t_call = Clock::now();
  if (p.rays_per_probe == 0 || probes.empty()) return Status::ok();
  size_t chunk = 0;
  vk::Buffer* samples = nullptr;
  bool passes = false;
  GIBAKE_TRY(reserve_chunks(vk, tracer, integrator, probes, p, options, chunk, samples, passes));
  const size_t depth = std::max<uint32_t>(1, options.in_flight);
  std::vector<Slot> slots(depth);
  PathResult out;
  GpuIntegrateResult integrals;
  size_t in_flight = 0;
  auto finish = [&](Slot& s) -> Status {
    auto t0 = Clock::now();
    GIBAKE_TRY(vk.wait(s.rec));
    times.wait += seconds_since(t0);
    s.used = false;
    --in_flight;
    t0 = Clock::now();
    PathTimes pt;
    tracer.collect(s.rec, s.path, out, &pt);
    if (integrator) integrator->collect(s.rec, s.integ, integrals);
    times.device += s.rec.device_seconds();
    times.path += pt.path;
    times.raygen += pt.raygen;
    times.stats += pt.stats;
    const Status st = done(s.part, out, integrator && !passes ? &integrals : nullptr);
    times.host += seconds_since(t0);
    return st;
  };
  size_t k = 0;
  for (size_t first = 0; first < probes.size(); first += chunk, ++k) {
    Slot& s = slots[k % depth];
    if (s.used) GIBAKE_TRY(finish(s));  // chunk k - depth: the oldest in flight
    auto t0 = Clock::now();
    s.part.assign(probes.begin() + first, probes.begin() + std::min(probes.size(), first + chunk));
    s.records.resize(s.part.size());
    p.fill(s.part, s.records.data());
    times.host += seconds_since(t0);
    t0 = Clock::now();
    GIBAKE_TRY(record_chunk(tracer, integrator, p, samples, passes, s));
    GIBAKE_TRY(vk.submit(s.rec));
    times.record += seconds_since(t0);
    s.used = true;
    times.in_flight = std::max<uint32_t>(times.in_flight, uint32_t(++in_flight));
    ++times.chunks;
  }
  for (size_t i = 0; i < depth; ++i) {  // the rest, oldest first
    Slot& s = slots[(k + i) % depth];
    if (s.used) GIBAKE_TRY(finish(s));
  }
  times.wall += seconds_since(t_call);
  return Status::ok();
}

}  // namespace gibake
