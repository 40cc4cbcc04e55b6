// The cost model behind `--backend auto`: wall-time estimates of a probe bake on the CPU backend and
// on a Vulkan GPU, from the workload (probes, rays, bounces, relocation rays, triangles), the CPU
// thread count and the kind of device. One pure function, so tests can ask it about made-up
// machines. Both sides are an affine function of the ray segments and the probes, the CPU's ray
// and probe terms divided by the thread count; the constants are fitted to the reference machine's
// bakes (docs/BENCHMARKS.md "Choosing the backend" names it and the runs).
#pragma once
#include <cstdint>
#include <string>

namespace gibake {

// What a bake will trace, known once its grid is planned. probes == 0: unknown (auto then takes
// the CPU: only a bake that states its work is worth opening a device for).
struct WorkloadEstimate {
  // The whole bake's probes, also in a shard (--shard), so that every shard of a bake decides alike
  // and the merge finds one backend in all of them.
  uint64_t probes = 0;
  double rays = 0.0;             // probe rays per probe (adaptive bakes: the expected mean)
  int bounces = 0;               // segments per probe ray: 1 + bounces
  uint64_t relocation_rays = 0;  // per probe, all iterations together (one segment each)
  uint64_t triangles = 0;        // the scene's: the GPU BVH build and upload grow with them
  int threads = 1;               // CPU threads the bake runs on
  bool known() const { return probes > 0 && rays > 0.0; }
  double segments() const;       // every ray segment the bake traces
};

// The Vulkan device auto would use, as the model sees it.
enum class GpuKind : uint8_t { None = 0, Discrete, Integrated, CpuDevice };

// Calibration (seconds, microseconds). CPU terms are thread-seconds: divided by the thread count.
namespace cost {
// CPU backend: Embree traversal and CPU shading of one ray segment, per thread.
constexpr double kCpuSegmentThreadUs = 0.39;
// CPU per-probe work besides its rays (integration, statistics, classification, the file), per thread.
constexpr double kCpuProbeThreadUs = 470.0;
// What every CPU bake pays whatever its size (import and set-up are outside both: they are common).
constexpr double kCpuFixedS = 0.13;
// Vulkan on a discrete GPU: one ray segment with shading.
constexpr double kGpuSegmentUs = 0.00087;
// Per probe on the device side (ray generation, integration and statistics kernels, read-back, the file).
constexpr double kGpuProbeUs = 5.0;
// Device and instance, pipelines, texel-pool packing and upload, first dispatches: what the light
// bakes pay.
constexpr double kGpuFixedS = 0.54;
// The GPU BVH build (Embree's rtcBuildBVH) and its upload, per triangle.
constexpr double kGpuTriangleUs = 0.34;
// An integrated GPU is taken as this many times slower than the calibration GPU per segment and probe
// (an assumption, not a fit: it keeps an integrated GPU from winning bakes a discrete one barely wins).
constexpr double kIntegratedSlowdown = 20.0;
}  // namespace cost

struct AutoDecision {
  bool vulkan = false;         // the GPU is the faster estimate
  double cpu_seconds = 0.0;    // estimates; 0 when no estimate was made
  double vulkan_seconds = 0.0;
  std::string reason;          // one clause: why
};

// The choice for `workload` with a device of `gpu` kind. An unknown workload, no GPU or a CPU Vulkan
// device (lavapipe): the CPU. Otherwise the smaller estimate, ties to the CPU.
AutoDecision decide_auto(const WorkloadEstimate& workload, GpuKind gpu);

// "auto → vulkan (est. cpu 2.9 s, vulkan 0.9 s)" and the reason; for the summary and notes.
std::string auto_decision_text(const AutoDecision& d);

}  // namespace gibake
