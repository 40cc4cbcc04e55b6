// Private to kernels/vulkan: the Vulkan handles behind Context, Buffer and Pipeline.
#pragma once
#include <vulkan/vulkan.h>

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "kernels/vulkan/context.h"
#include "kernels/vulkan/memory_pool.h"

namespace gibake::vk {

// A zeroed Vulkan struct with its sType (aggregate initialisation would trip -Wextra).
template <class T>
T make(VkStructureType type) {
  T value{};
  value.sType = type;
  return value;
}

Status vk_error(const char* call, VkResult r);
#define GIBAKE_VK(call)                                  \
  do {                                                   \
    const VkResult _r = (call);                          \
    if (_r != VK_SUCCESS) return vk_error(#call, _r);    \
  } while (0)

// An instance with or without the validation layer; `messenger` is set when validation is on.
struct Instance {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  bool validation = false;
  uint32_t* error_count = nullptr;   // where the messenger counts errors
  std::string* first_error = nullptr;
  void destroy();
};
Status create_instance(bool validation, uint32_t* error_count, std::string* first_error, Instance& out);
DeviceInfo describe_device(VkPhysicalDevice device, uint32_t index);

struct Buffer::Impl {
  VkDevice device = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  MemoryPool* pool = nullptr;  // its context's, which outlives it
  MemoryPool::Piece memory;    // bound at memory.offset of memory.memory
  void* mapped = nullptr;      // staging buffers only
  uint64_t size = 0;
  ~Impl();
};

struct Pipeline::Impl {
  VkDevice device = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  uint32_t bindings = 0, push_bytes = 0;
  std::string name;
  ~Impl();
};

// The context's handles (context.cpp; recording.cpp submits through them too).
struct Context::Impl {
  Instance inst;
  uint32_t errors = 0;
  std::string first_error;
  VkPhysicalDevice phys = VK_NULL_HANDLE;
  DeviceInfo info;
  VkPhysicalDeviceMemoryProperties mem{};
  VkPhysicalDeviceLimits limits{};
  DeviceLimits lim;  // what gibake checks against (Context::limits)
  VkDevice device = VK_NULL_HANDLE;
  MemoryPool memory;  // every buffer's memory; freed after them, before the device
  uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  bool timestamps = false;
  bool float64 = false;  // shaderFloat64 enabled
  double timestamp_ns = 1.0;
  // One staging buffer each way reused by every copy (pinned host memory is slow to allocate: a fresh
  // one per copy can cost more than the copy): uploads through 8 MiB, readbacks through
  // one grown up to kStagingBytes.
  // Reads go through host-cached memory where the device has it: uncached (write-combined) memory
  // reads at a fraction of the bandwidth.
  std::unique_ptr<Buffer::Impl> staging, readback;
  // Held around every use of `cmd`, the staging buffers and the queue: the bake's set-up uploads
  // the BVH and the texture pool from two tasks at once (bake/run/bake_setup.cpp).
  std::mutex queue_mutex;
  // Pipelines made ahead (Context::create_pipelines_beside), in spec order; `made` counts those done.
  struct Ahead {
    PipelineSpec spec;
    std::unique_ptr<Pipeline::Impl> pipeline;
    Status status = Status::ok();
    bool taken = false;
  };
  std::vector<Ahead> ahead;
  size_t ahead_made = 0, ahead_taken = 0;
  std::mutex ahead_mutex;
  std::condition_variable ahead_done;
  std::thread ahead_thread;

  ~Impl();
  int memory_type(uint32_t bits, VkMemoryPropertyFlags want) const;
  bool has_memory(VkMemoryPropertyFlags want) const;
  Status make_buffer(uint64_t bytes, VkBufferUsageFlags usage, VkMemoryPropertyFlags want, Buffer::Impl& b,
                     const char* what, int type = -1);
  // Device-local memory the host can write, as large as the device's memory (resizable BAR on a GPU;
  // any memory of a CPU device): Context::create_filled_buffer writes into it, no staging. -1: none.
  int direct_type = -1;
  // A host-visible staging buffer of `bytes` (cached where the device has it, when for_reading).
  Status make_staging(uint64_t bytes, bool for_reading, Buffer::Impl& b);
  // The upload staging buffer, or the readback one at least min(bytes, kStagingBytes) large.
  Status staging_for(uint64_t bytes, bool for_reading, Buffer::Impl*& out);
  // Records `record` into the one command buffer, submits it and waits.
  Status submit(const std::function<void(VkCommandBuffer)>& record);
  Status create_device(uint32_t index, bool allow_float64);
  // Fills `lim` from the device (after create_device); `max_groups` > 0 lowers the group count in x.
  void read_limits(uint32_t max_groups, uint64_t forced_memory);
  uint64_t device_memory_budget() const;
};

// Checks a dispatch against its pipeline (binding count, push bytes, no empty buffer) and its grid
// against the device's maxComputeWorkGroupCount (a flat grid folded first).
Status check_dispatch(const Dispatch& d, const Context::Impl& im);
// The x, y, z group counts a dispatch runs with: `groups`, or its flat grid folded into x and y.
void dispatch_grid(const Dispatch& d, const DeviceLimits& lim, uint32_t out[3]);
// Binds and dispatches `d` with descriptor set `set`, between two timestamps when `qpool` is set,
// then a barrier making its writes visible to later dispatches and copies.
void record_dispatch(VkCommandBuffer cb, const Dispatch& d, const DeviceLimits& lim, VkDescriptorSet set,
                     VkQueryPool qpool, uint32_t query);
// Allocates one descriptor set per dispatch from `dpool` (sized by the caller) and points it at the
// dispatch's buffers.
Status write_descriptor_sets(VkDevice device, VkDescriptorPool dpool, const std::vector<Dispatch>& dispatches,
                             std::vector<VkDescriptorSet>& sets);
// A global barrier: every earlier compute or transfer write visible to later compute and transfer work.
void full_barrier(VkCommandBuffer cb);

}  // namespace gibake::vk
