// The one CPU/GPU switch (--backend, --vulkan-device): which backend a bake runs on, chosen once
// from the settings and the Vulkan devices present. `auto` takes a discrete or integrated GPU and
// otherwise the CPU; Mesa's lavapipe (a CPU Vulkan device) only when named; `vulkan` without a
// usable device is a RuntimeFailure (exit 4).
#pragma once
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <thread>
#include <vector>

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
};

struct BackendChoice {
  Backend backend = Backend::Cpu;  // Cpu or Vulkan, never Auto
  vk::DeviceInfo device;           // the chosen device when Vulkan
};

const char* backend_name(Backend b);
// "auto" | "cpu" | "vulkan"; false for anything else.
bool parse_backend(const std::string& text, Backend& out);

// The choice for these devices (pure: tests pass made-up lists).
Status choose_backend(const BackendSettings& settings, const std::vector<vk::DeviceInfo>& devices, BackendChoice& out);
// Lists the devices (vk::list_devices) and chooses.
Status resolve_backend(const BackendSettings& settings, BackendChoice& out);

// `gibake info --devices`: every Vulkan device (index, name, type, driver, memory, API) and which
// one `--backend auto` would take; text lines or a JSON object {"devices": [...], "auto": index|null}.
Status write_device_list(bool json, std::ostream& out);

// Opens a Vulkan context on the chosen device.
Status open_vulkan(const BackendChoice& choice, const BackendSettings& settings, std::unique_ptr<vk::Context>& out);

// Opens the chosen Vulkan device on a background thread, so that the driver's instance and device
// creation (0.14-0.18 s with NVIDIA's driver on the H100 machine) overlaps work that needs no
// device, such as the import. The backend is resolved in start() itself, so a missing device still
// fails at once; on the CPU backend no thread starts. The bake takes the context over with take().
class VulkanWarmup {
 public:
  VulkanWarmup() = default;
  VulkanWarmup(const VulkanWarmup&) = delete;
  VulkanWarmup& operator=(const VulkanWarmup&) = delete;
  ~VulkanWarmup();
  Status start(const BackendSettings& settings);
  // Waits for the device; the choice made by start() and the open context (null on the CPU), or the
  // error opening it. Once only.
  Status take(BackendChoice& choice, std::unique_ptr<vk::Context>& out);

 private:
  std::thread thread_;
  BackendChoice choice_;
  Status status_;
  std::unique_ptr<vk::Context> vk_;
};

}  // namespace gibake
