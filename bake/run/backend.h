// The one CPU/GPU switch (--backend, --vulkan-device): which backend a bake runs on, chosen once
// from the settings, the workload and the Vulkan devices present. `auto` (the default) asks the
// cost model (bake/run/backend_cost.h) whether a discrete or integrated GPU would finish the bake
// sooner than the CPU, and never takes a CPU Vulkan device (Mesa's lavapipe: only `--backend vulkan
// --vulkan-device lavapipe`), so machines without a GPU bake exactly as `--backend cpu`. `vulkan`
// without a usable device is a RuntimeFailure (exit 4).
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bake/run/backend_cost.h"
#include "io/status.h"
#include "kernels/vulkan/context.h"

namespace gibake {

enum class Backend : uint8_t { Auto = 0, Cpu = 1, Vulkan = 2 };

struct BackendSettings {
  Backend backend = Backend::Cpu;
  // Index or (case-insensitive substring of a) name from `gibake info --devices`, or "lavapipe";
  // empty: the first discrete GPU, else the first integrated one.
  std::string vulkan_device;
  bool validation = false;  // Khronos validation layer (tests)
  bool float64 = true;      // false (tests): use no doubles on the device, as on a device without them
  // Tests: auto weighs a CPU Vulkan device (lavapipe) as a discrete GPU, so that its speculative
  // open, decision and close run where no GPU exists.
  bool auto_cpu_device_as_gpu = false;
  // Tests: the Vulkan trace's chunks in flight and rays per chunk (GpuSession); 0: the defaults.
  uint32_t vulkan_in_flight = 0;
  uint64_t vulkan_chunk_rays = 0;
  // Tests: probes per group of the device's adaptive passes (a multiple of 512); 0: as many as the
  // device's largest buffer holds accumulators for (DdgiDevice::pass_group_probes).
  uint32_t vulkan_pass_group_probes = 0;
  // Tests: every volume of a bake traced in a stage of its own, not together with the volumes after
  // it (bake_ddgi_together), to check that tracing them together changes no byte.
  bool vulkan_volumes_apart = false;
  // Tests: a lower maxComputeWorkGroupCount[0] than the device's (vk::ContextOptions); 0: the device's.
  uint32_t vulkan_max_group_count = 0;
  // Tests: less device memory than the device has (vk::ContextOptions::device_memory); 0: the device's.
  uint64_t vulkan_device_memory = 0;
  // The GPU BVH cache's folder (bake/vulkan/bvh_cache.h; `gibake bake --cache-dir`); empty: none.
  // Never part of a settings JSON: a loaded tree is the one the build makes.
  std::string bvh_cache_dir{};
  // For `auto`: what the bake will trace, filled in by the bake once its grid is planned (not a user
  // setting; never part of a settings JSON). Unknown: auto takes the CPU.
  WorkloadEstimate workload{};
};

struct BackendChoice {
  Backend backend = Backend::Cpu;  // Cpu or Vulkan, never Auto
  vk::DeviceInfo device;           // the chosen device when Vulkan
  bool automatic = false;          // chosen by `auto`: `decision` says why
  AutoDecision decision{};
};

const char* backend_name(Backend b);
// "auto" | "cpu" | "vulkan"; false for anything else.
bool parse_backend(const std::string& text, Backend& out);

// The choice for these devices (pure: tests pass made-up lists). For `auto`, the cost model's
// decision on settings.workload and the device auto_candidate() names.
Status choose_backend(const BackendSettings& settings, const std::vector<vk::DeviceInfo>& devices, BackendChoice& out);
// The device `auto` would weigh: the named one when --vulkan-device names one, else the first
// discrete GPU, else the first integrated one, else a CPU device (which the model never takes);
// null when none. Its kind for the cost model.
const vk::DeviceInfo* auto_candidate(const BackendSettings& settings, const std::vector<vk::DeviceInfo>& devices);
GpuKind gpu_kind(const vk::DeviceInfo* device, bool cpu_device_as_gpu = false);
// Lists the devices (vk::list_devices) and chooses.
Status resolve_backend(const BackendSettings& settings, BackendChoice& out);

// `gibake info --devices`: every Vulkan device (index, name, type, driver, memory, API) and which
// one `--backend auto` would take; text lines or a JSON object {"devices": [...], "auto": index|null}.
Status write_device_list(bool json, std::ostream& out);

// Opens a Vulkan context on the chosen device.
Status open_vulkan(const BackendChoice& choice, const BackendSettings& settings, std::unique_ptr<vk::Context>& out);

// Opens the chosen Vulkan device on a background thread, so that the driver's instance and device
// creation (a fraction of a second with a desktop driver) overlaps work that needs no
// device, such as the import and the host half of the set-up. `vulkan`: the thread lists the
// devices and opens the one asked for; listed() says whether there is one (the import stops early
// once listing_failed(); choose() waits for a listing still under way). `auto`: the thread lists the devices
// and opens auto's candidate GPU speculatively (none: nothing opens); choose() then decides from
// the workload, which is known only once the grid is planned, as soon as the devices are listed:
// when the CPU wins it does not wait for the device to open,
// which is then closed beside the bake. On the CPU backend no thread starts. The bake chooses
// first, does its host-side set-up, and takes the context over with take_device().
class VulkanWarmup {
 public:
  VulkanWarmup() = default;
  VulkanWarmup(const VulkanWarmup&) = delete;
  VulkanWarmup& operator=(const VulkanWarmup&) = delete;
  ~VulkanWarmup();
  Status start(const BackendSettings& settings);
  // `vulkan`: waits for the listing; the error (exit 4) when no usable device matches. Others: ok.
  Status listed();
  // True once the listing found no device for `vulkan`; does not wait.
  bool listing_failed();
  // The choice (for `auto`: the cost model's on `workload`) once the devices are listed, without
  // waiting for the device to open. Once only, then take_device().
  Status choose(const WorkloadEstimate& workload, BackendChoice& choice);
  // Waits for the chosen device and hands its context over (null on the CPU); `vulkan`: the error
  // opening it; `auto`: a device that did not open turns `choice` into the CPU's, saying why.
  Status take_device(BackendChoice& choice, std::unique_ptr<vk::Context>& out);
  // choose(), then take_device().
  Status take(const WorkloadEstimate& workload, BackendChoice& choice, std::unique_ptr<vk::Context>& out);

 private:
  Status start_named(const BackendSettings& settings);  // --backend vulkan's start
  void mark_listed(const Status& status);              // wakes listed()'s waiters

  std::thread thread_;
  std::thread closer_;  // closes a speculative device the CPU won over
  Backend backend_ = Backend::Cpu;
  // Set once the devices are listed (auto: kind_ known; the device may still be opening).
  std::mutex listed_mutex_;
  std::condition_variable listed_cv_;
  bool listed_ = false;
  Status listed_status_;  // vulkan: whether the listed devices hold the one asked for
  std::atomic<bool> cancelled_{false};  // the CPU won before the device began to open: do not open it
  BackendChoice choice_;                // auto: the candidate device (choice_.device) when there is one
  GpuKind kind_ = GpuKind::None;
  Status status_;
  std::unique_ptr<vk::Context> vk_;
};

}  // namespace gibake
