// The DDGI bake's stages as one class (bake/ddgi/ddgi.cpp), shared by bake_ddgi, which runs them in
// order for one volume, and bake_ddgi_together (bake/ddgi/ddgi_together.cpp), which runs them for
// several volumes and traces their probes in one stage. Internal to bake/ddgi.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bake/ddgi/classify.h"
#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/ddgi_device.h"
#include "bake/ddgi/ddgi_memory.h"
#include "bake/ddgi/probe_integrate.h"
#include "bake/ddgi/trace_stage.h"
#include "bake/run/arena.h"
#include "bake/run/bake_setup.h"
#include "bake/scene/emitters.h"
#include "bake/scene/sky.h"
#include "bake/trace/path_gather.h"
#include "bake/voxel/voxelize.h"
#include "io/timer.h"
#include "kernels/octahedral.h"

namespace gibake {

// One probe bake from grid to result: each stage a method, reading what the ones before left in
// the members. Declaration order is destruction order in reverse: the closed-mesh check's task is
// waited for before what it reads (the arena, its positions) goes away.
class DdgiBake {
 public:
  DdgiBake(const Scene& scene, const DdgiSettings& s, const RunContext& run, const Context& ctx, DdgiResult& result,
           DdgiReport& report)
      : scene_(scene), s_(s), run_(run), ctx_(ctx), result_(result), report_(report), desc_(result.desc) {}

  Status plan();
  uint64_t memory_need(bool vulkan, bool vulkan_host_records = false) const;
  Status check_memory(bool vulkan, bool final) const;
  Status check_need(uint64_t need, bool final, const std::string& route = "") const;
  Status place_grid();
  Status placement_voxels();
  void start_closed_mesh_check();
  Status set_up();
  void start_integrator();
  // The trace stage from the settings (fill_trace_stage), its device set-up begun beside relocation
  // (begin_trace_setup: for `stage`, which outlives the wait in trace_setup_done, else its own).
  void fill_trace_stage();
  void begin_trace_setup(const TraceStage* stage = nullptr);
  void start_trace_setup() {
    fill_trace_stage();
    begin_trace_setup();
  }
  void leave_out_far_probes();
  Status relocate();
  Status trace();
  // The trace's two waits (trace_probes' `begun` and `integrators`): the device's set-up, with the
  // memory judged again where the device keeps the records on the host; the integrator, readied.
  Status trace_setup_done();
  Status trace_begun();
  ProbeIntegrator& trace_integrator();

  // What bake_ddgi_together reads and sets around a trace of several volumes.
  int32_t probe_count() const { return probe_count_; }
  const std::vector<int32_t>& traced_probes() const { return all_probes_; }
  const std::vector<uint8_t>& left_out() const { return left_out_; }
  const TraceStage& trace_stage() const { return trace_stage_; }
  DdgiDevice& device() { return *device_; }
  const DdgiSettings& settings() const { return s_; }
  float max_distance() const { return desc_.max_distance; }
  // The shape of the working set memory_need estimates; the figure of several volumes' is checked
  // and recorded as each one's (report.memory_estimate).
  DdgiMemoryShape memory_shape(bool vulkan, bool vulkan_host_records = false) const;
  // The probes' counters after the trace, and the stage's seconds under `stage` (none: traced with
  // an earlier volume, whose stage holds the time).
  void traced(std::vector<TraceCounters> counters, double seconds, const std::string& stage = "trace");
  // With a shard in the run context: hands the shard's probes over (the merge finishes the bake).
  Status hand_off(bool& handed_off, double seconds_total);
  Status classify();
  void finish(double seconds_total);
  void filter();
  void coarsen_depth();
  void release_beside();

  // Where probe p's rays leave from: its rest position and its relocation offset.
  kernels::float3 probe_position(int32_t p) const {
    const auto rest = probe_rest_position(desc_, p);
    return kernels::float3{rest[0] + offsets_[p * 3], rest[1] + offsets_[p * 3 + 1], rest[2] + offsets_[p * 3 + 2]};
  }
  // Every probe where its rays left from (rest + relocation offset), x y z.
  std::vector<float> final_positions() const {
    std::vector<float> out(size_t(probe_count_) * 3);
    for (int32_t p = 0; p < probe_count_; ++p) kernels::store3(&out[size_t(p) * 3], probe_position(p));
    return out;
  }
  std::function<kernels::float3(int32_t)> position_fn() const {
    return [this](int32_t p) { return probe_position(p); };
  }

 private:
  const Scene& scene_;
  const DdgiSettings& s_;
  const RunContext& run_;
  const Context& ctx_;
  DdgiResult& result_;
  DdgiReport& report_;
  DdgiVolumeDesc& desc_;

  int32_t probe_count_ = 0;
  uint32_t max_rays_ = 0;
  kernels::AtlasLayout irr_layout_, depth_layout_;
  Sky sky_;
  std::vector<kernels::ShadeLight> lights_;
  std::unique_ptr<tbb::task_arena> arena_;

  // The closed-mesh check: a task beside every stage up to the classification (it needs no ray).
  ClosedMeshCheck closed_check_;
  std::vector<float> rest_positions_;
  float reach_[3] = {0.f, 0.f, 0.f};  // how far relocation may move a probe from its rest position
  BesideTask check_task_;             // after what it reads and writes: destroyed (waited for) first

  // The voxels the grid was fitted to (run context's, else built here; moved to the set-up after).
  VoxelGrid placement_voxels_;
  const VoxelGrid* placement_voxels_ref_ = nullptr;
  bool keep_placement_voxels_ = false;

  // The set-up: what the run context gave, else what this bake built.
  BakeSetup local_setup_;
  BakeSetup* built_ = nullptr;
  const PreparedScene* prepared_ = nullptr;
  const TextureLod* texture_lod_ = nullptr;
  const VoxelGrid* voxels_ = nullptr;
  TraceSetup trace_setup_;
  EmitterTable emitters_;
  PathSetup path_;

  std::vector<int32_t> all_probes_;  // the probes relocated and traced: a shard's range, near surfaces
  std::vector<uint8_t> left_out_;    // per probe: 1 when near_surface_reach left it out (no rays)
  std::vector<float> offsets_;
  std::vector<float> fib_reloc_, fib_rays_;  // unrotated spherical Fibonacci sets (probes rotate them)
  std::vector<uint64_t> reloc_rays_;
  std::vector<uint8_t> moved_;
  std::unique_ptr<ProbeIntegrator> integ_;
  // Builds integ_ (hundreds of MB zeroed at 80,640 probes) beside the set-up, relocation and the
  // device's trace set-up; after integ_, so destroyed (waited for) before it.
  BesideTask integ_task_;
  std::vector<TraceCounters> counters_;
  std::unique_ptr<DdgiDevice> device_;  // after the set-up it runs on: destroyed first
  TraceStage trace_stage_;
  Status trace_setup_status_ = Status::ok();
  BesideTask trace_setup_task_;  // begins the trace on device_: after it, so waited for before it goes
};

// bake_ddgi's stages up to the set-up (the plan, the closed-mesh check and the integrator begun
// beside), and those after the trace (a shard's hand-off, or classification to the release).
Status start_ddgi_bake(DdgiBake& bake, const RunContext& run);
Status end_ddgi_bake(DdgiBake& bake, DdgiReport& report, Clock::time_point start);

}  // namespace gibake
