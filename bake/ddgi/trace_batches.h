// The trace stage's bookkeeping, the same whichever device traces: where each probe's records of a
// batch go (a scratch, or its list when --target-error keeps every batch), its running statistics,
// and when it is finished by the ProbeIntegrator. A device (bake/ddgi/ddgi_device.h) fills records
// and calls batch_done, or reduces a batch itself and calls finish_tested.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

#include "bake/ddgi/probe_integrate.h"
#include "bake/ddgi/trace_stage.h"
#include "kernels/vec.h"

namespace gibake {

// The per-ray value whose relative error --target-error bounds (RunningStats over a probe's rays in
// ray order): the ray's luminance (kernels::luminance, in float), plus its paired emitter sample's
// when the probe samples the lights (`light`, else null; both scaled to the same 4pi/N norm): the
// combined estimator's terms, so the error is that of what is integrated. Its GLSL twin is
// ray_stop_value in kernels/shaders/stop_value.glsl (the device's statistics,
// bake/vulkan/probe_stats.h): change both together, operation for operation, so that the CPU and
// the device make the same stop decisions from the same rays.
inline double ray_stop_value(const float* radiance, const float* light) {
  const double x = double(kernels::luminance(radiance));
  return light ? x + double(kernels::luminance(light)) : x;
}

class ProbeBatches {
 public:
  // `integrators`: one, or one per part of the stage (TraceStage::parts), each finishing its part's
  // probes by their index in it.
  ProbeBatches(const TraceStage& stage, size_t probe_count, std::vector<ProbeIntegrator*> integrators,
               std::vector<TraceCounters>& counters);

  const TraceStage& stage() const { return st_; }
  // The first part's integrator: what every part shares (the parts of a stage have the same miss
  // depth, ProbeIntegrator::max_distance).
  ProbeIntegrator& integrator() { return *integ_[0]; }
  // With --target-error: every batch's records are kept until the probe is finished.
  bool keeps_hits() const { return adaptive_; }
  size_t probe_count() const { return running_.size(); }
  TraceCounters& counters(int32_t p) { return counters_[p]; }
  RunningStats& running(int32_t p) { return running_[p]; }
  // Back-face hits over probe p's rays so far: batch_done takes them from its counters; a device
  // that keeps its statistics itself between batches sets them with its running statistics.
  uint32_t& back_faces(int32_t p) { return back_faces_[p]; }

  // Whether the probes sample the emitters themselves (TraceStage::probe_lights): every record then
  // has a paired emitter sample (trace_probe_paths' `lights`).
  bool probe_lights() const { return st_.probe_lights; }
  // Where probe p's records of this batch go: appended to its list (kept), else the calling
  // thread's scratch. Probes may be filled concurrently, one thread each. `lights` (optional)
  // receives where the batch's paired emitter samples go (null without probe_lights).
  kernels::HitRecord* records(int32_t p, kernels::RaySample** lights = nullptr);
  // After a batch of probe p: its running statistics; unless records are kept, its integration (from
  // `integrals` when the device computed them). `lights`: the batch's emitter samples (probe_lights).
  void batch_done(int32_t p, const kernels::HitRecord* h, const ProbeIntegrals* integrals,
                  const kernels::RaySample* lights = nullptr);
  // A batch the device reduced to statistics itself (one batch per probe, integrals computed there).
  void finish_tested(int32_t p, const ProbeRayTest& test, const ProbeIntegrals& integrals);
  // Kept records (with --target-error), and finishing from them (integrals: null, on the CPU).
  const std::vector<kernels::HitRecord>& kept(int32_t p) const { return hits_[p]; }
  const std::vector<kernels::RaySample>& kept_lights(int32_t p) const { return lights_[p]; }
  void finish_kept(int32_t p, const ProbeIntegrals* integrals);
  // The relative error probe p's batches are decided on: its own count of rays with the mean
  // relative variance per ray of its grid neighbours in its block (TraceStage::counts), not its
  // own. A probe's own variance comes out low exactly when its rays missed the rare bright paths
  // that also make its mean low; deciding on it stops or starves the probes that came out dark,
  // so a bake lit through rare paths (white rooms, light through gaps) came out dark. Its
  // neighbours' rays are independent of its own, so its mean stays unbiased whatever they decide;
  // the light changes little from one probe to the next, so their variance predicts its own. Its
  // own statistics when no neighbour has any (and without counts). With --target-error it is also
  // the relative error a probe's statistics record (DdgiProbeStats::relative_error).
  double decision_error(int32_t p) const;
  // Whether probe p's rays so far put it inside geometry beyond doubt: its back-face share above
  // TraceStage::backface_threshold t by three standard errors of a share t over its rays
  // (3 sqrt(t (1 - t) / n)), so that its own batches would almost never bring it back under t. Its
  // verdict on the rays it has is then Inactive, and its light is never read: it stops, and leaves
  // the block's budget to the probes that are not inside.
  bool inside(int32_t p) const;
  // The probes of `pending` that need another batch (none without target_error): not inside,
  // below max_rays after one more and their decision_error not below target_error. With a
  // ray_budget, decided per block of probes (io/results/ddgi_shard.h: kProbeBlock), each block
  // holding ray_budget x its probes not inside, which share it: only those above the error level the block's budget
  // left can bring its probes down to (water-filling: the noisiest probes get the rays), at most as many as it holds,
  // largest error first; in `pending`'s order. Decided from the statistics alone: the same for any thread count, and a
  // block's decisions read its own probes only, so a shard that owns the block decides as the one-go bake does.
  std::vector<int32_t> unfinished(const std::vector<int32_t>& pending) const;

 private:
  // The probes of `next` (all above the target) that the ray budget lets go on (unfinished's rule).
  std::vector<int32_t> within_budget(const std::vector<int32_t>& next) const;
  // One block's share: keep[i] set for the positions `at` in `next` (the block's probes) that go on.
  void block_within_budget(uint32_t block, const std::vector<int32_t>& next, const std::vector<size_t>& at,
                           std::vector<uint8_t>& keep) const;

  // The integrator that finishes probe p, and p's index there.
  ProbeIntegrator& integrator_of(int32_t p, int32_t& local) const;

  const TraceStage& st_;
  const bool adaptive_;
  std::vector<ProbeIntegrator*> integ_;
  std::vector<TraceCounters>& counters_;
  std::vector<RunningStats> running_;
  std::vector<uint32_t> back_faces_;
  std::vector<std::vector<kernels::HitRecord>> hits_;  // kept batches only
  std::vector<std::vector<kernels::RaySample>> lights_;  // kept batches' emitter samples (probe_lights)
  tbb::enumerable_thread_specific<std::vector<kernels::HitRecord>> scratch_;
  tbb::enumerable_thread_specific<std::vector<kernels::RaySample>> light_scratch_;
};

}  // namespace gibake
