// One small Vulkan compute context: instance, one physical device and its compute queue, buffers
// (device-local, filled and read back through staging), compute pipelines from embedded SPIR-V,
// and dispatches timed with timestamp queries. No global state: everything hangs off a Context;
// errors are Status values (RuntimeFailure). Vulkan's headers stay inside kernels/vulkan/*.cpp.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "io/status.h"

namespace gibake::vk {

// A physical device as `gibake info --devices` lists it.
struct DeviceInfo {
  uint32_t index = 0;          // position in the instance's enumeration order
  std::string name;
  std::string type;            // discrete, integrated, virtual, cpu, other
  std::string driver;          // driver name and info (VK_KHR_driver_properties), or the version number
  std::string api;             // "1.3.239"
  uint64_t device_memory = 0;  // bytes in the largest device-local heap
  bool compute = false;        // has a queue family with compute: usable by gibake
  bool is_gpu() const { return type == "discrete" || type == "integrated"; }
  bool is_lavapipe() const;    // Mesa's CPU device (llvmpipe)
};

// Every physical device the Vulkan loader finds (a temporary instance). No loader or no ICD: an
// empty list and ok; only a broken loader is an error.
Status list_devices(std::vector<DeviceInfo>& out);

struct ContextOptions {
  uint32_t device_index = 0;
  // Khronos validation layer when installed (tests); its errors are counted, see validation_errors().
  bool validation = false;
  // false: act as a device without shaderFloat64 (tests of the routes such devices take).
  bool float64 = true;
  // Tests only: a lower maxComputeWorkGroupCount[0] (x) than the device's, so that the folding of
  // large grids into rows runs where the device's own limit does not bind. 0: the device's.
  uint32_t max_group_count = 0;
  // Tests only: less device-local memory than the device has (bytes), so that the bake's checks
  // against it and the batches that shrink to fit it run on any device. 0: the device's.
  uint64_t device_memory = 0;
};

// The device limits gibake's dispatches and buffers are checked against (VkPhysicalDeviceLimits,
// maxMemoryAllocationSize from Vulkan 1.1).
struct DeviceLimits {
  uint32_t group_count[3] = {65535, 65535, 65535};  // maxComputeWorkGroupCount
  uint64_t storage_buffer_range = 0;                // maxStorageBufferRange
  uint64_t memory_allocation = 0;                   // maxMemoryAllocationSize
  uint32_t shared_memory = 16384;                   // maxComputeSharedMemorySize
  // Storage buffers one kernel may bind: the smaller of maxPerStageDescriptorStorageBuffers and
  // maxDescriptorSetStorageBuffers (every kernel binds storage buffers only, in one set).
  uint32_t storage_buffers = 4;
  // Device-local memory a bake may fill: the largest device-local heap, or less where
  // VK_EXT_memory_budget says less of it is this process's to take (other processes hold the rest),
  // or ContextOptions::device_memory. `device_memory_source` says which.
  uint64_t device_memory = 0;
  const char* device_memory_source = "device-local heap";
};

class Context;

// Where the context's buffers live (kernels/vulkan/memory_pool.h): pieces of a few large blocks of
// device memory, a dedicated allocation for a buffer larger than half a block.
struct MemoryStats {
  uint32_t blocks = 0;       // live blocks
  uint32_t dedicated = 0;    // live dedicated allocations
  uint32_t pieces = 0;       // live buffers in blocks
  uint64_t block_bytes = 0;  // bytes of every live block
  uint64_t device_local_bytes = 0;  // bytes of every live allocation (block or dedicated) in device-local memory
  uint64_t allocations = 0;  // vkAllocateMemory calls so far (blocks and dedicated)
};

// A storage buffer in device-local memory. Move-only; destroyed before its Context.
class Buffer {
 public:
  Buffer();
  ~Buffer();
  Buffer(Buffer&&) noexcept;
  Buffer& operator=(Buffer&&) noexcept;
  uint64_t size() const;
  bool valid() const { return impl_ != nullptr; }
  struct Impl;
  Impl* impl() const { return impl_.get(); }

 private:
  friend class Context;
  std::unique_ptr<Impl> impl_;
};

// What a compute pipeline is made from (Context::create_pipeline): its SPIR-V, `bindings` storage
// buffers at set 0, bindings 0..n-1, and `push_bytes` of push constants.
struct PipelineSpec {
  const uint32_t* spirv = nullptr;
  size_t words = 0;
  uint32_t bindings = 0, push_bytes = 0;
  const char* name = "";
  uint32_t shared_bytes = 0;  // the shader's workgroup (shared) memory, checked against the device's
};

// A compute pipeline: `bindings` storage buffers at set 0, bindings 0..n-1, and `push_bytes` of
// push constants. Move-only; destroyed before its Context.
class Pipeline {
 public:
  Pipeline();
  ~Pipeline();
  Pipeline(Pipeline&&) noexcept;
  Pipeline& operator=(Pipeline&&) noexcept;
  struct Impl;
  Impl* impl() const { return impl_.get(); }

 private:
  friend class Context;
  std::unique_ptr<Impl> impl_;
};

// One compute dispatch of a run: the pipeline, its buffers in binding order, push constants, and
// either `groups` (each within the device's maxComputeWorkGroupCount, else the run fails) or
// `flat_groups`: a line of that many workgroups that the context folds into x and y within the
// device's limits; such a shader numbers its invocations with GIBAKE_FLAT_INVOCATION
// (kernels/shaders/gpu_types.h) and returns past its count (the last row may run over).
struct Dispatch {
  const Pipeline* pipeline = nullptr;
  std::vector<const Buffer*> buffers;
  std::vector<uint8_t> push;
  uint32_t groups[3] = {1, 1, 1};
  uint64_t flat_groups = 0;
};

template <class T>
std::vector<uint8_t> push_bytes(const T& value) {
  const auto* p = reinterpret_cast<const uint8_t*>(&value);
  return std::vector<uint8_t>(p, p + sizeof(T));
}

// A submission recorded on the host and run without waiting (Context::submit, then Context::wait),
// so that the host can prepare the next one, or read the previous one's results, while the device
// works: several recordings in flight keep one queue busy. Its steps run in order, each seeing every
// earlier step's writes and everything submitted before it. Uploaded bytes are copied when recorded;
// downloads land in the recording's own host memory, readable after wait() until the next submit.
// Every buffer and pipeline a step names must live until wait() returns. Move-only; destroyed
// before its Context (it waits for its own submission first).
class Recording {
 public:
  Recording();
  ~Recording();
  Recording(Recording&&) noexcept;
  Recording& operator=(Recording&&) noexcept;

  void upload(Buffer& dst, const void* data, uint64_t bytes, uint64_t offset = 0);
  // The dispatch's index, for dispatch_seconds().
  size_t dispatch(Dispatch d);
  // The download's index, for result().
  size_t download(const Buffer& src, uint64_t bytes, uint64_t offset = 0);

  bool in_flight() const;
  // After wait(): a download's bytes; each dispatch's device seconds (record order; 0 where the
  // queue has no timestamps); the device seconds from the submission's first step to its last.
  const void* result(size_t index) const;
  const std::vector<double>& dispatch_seconds() const;
  double device_seconds() const;

  struct Impl;

 private:
  friend class Context;
  std::unique_ptr<Impl> impl_;
};

class Context {
 public:
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  static Status create(const ContextOptions& options, std::unique_ptr<Context>& out);
  // Lists the devices and opens the one `choose` picks on the same instance (one driver start-up
  // instead of two: list_devices and create each pay the driver's instance creation, which is slow
  // on discrete GPUs). `choose` sees every device (an empty list when there is no
  // ICD) and returns false to open none (out stays null); options.device_index is ignored.
  using DeviceChooser = std::function<bool(const std::vector<DeviceInfo>& devices, uint32_t& index)>;
  static Status create_chosen(const ContextOptions& options, const DeviceChooser& choose,
                              std::unique_ptr<Context>& out);

  const DeviceInfo& device() const;
  bool validation_enabled() const;
  // Whether kernels may use doubles (shaderFloat64, enabled when the device has it).
  bool shader_float64() const;
  // Errors the validation layer reported so far, and the first one's text.
  uint32_t validation_errors() const;
  std::string first_validation_error() const;
  // Largest single storage buffer the device accepts (maxStorageBufferRange and
  // maxMemoryAllocationSize, capped by memory).
  uint64_t max_buffer_bytes() const;
  // The limits dispatches, buffers and pipelines are checked against (with ContextOptions'
  // test-only max_group_count applied).
  const DeviceLimits& limits() const;
  MemoryStats memory_stats() const;
  // DeviceLimits::device_memory, and the device memory this context holds now (its blocks and
  // dedicated allocations).
  uint64_t device_memory() const;
  uint64_t device_bytes() const;
  // RuntimeFailure when `need` more bytes on top of `held` would not fit device_memory(): one line
  // naming `what`, the figure, the device's memory and `lowers` (what makes the figure smaller).
  Status check_device_memory(uint64_t need, uint64_t held, const std::string& what, const std::string& lowers) const;

  Status create_buffer(uint64_t bytes, Buffer& out, const char* what);
  // A device-local buffer of `bytes` (at least 16) holding `data`. Where the device has host-visible
  // device-local memory as large as its memory (resizable BAR; a CPU device), the host writes it
  // there side by side in the calling arena: no staging, no copy on the queue; else create_buffer
  // and upload.
  Status create_filled_buffer(const void* data, uint64_t bytes, Buffer& out, const char* what);
  // The same for `count` elements, adding the buffer's size (16 bytes at least) to `total`.
  template <class T>
  Status create_filled_buffer(const T* data, size_t count, Buffer& out, const char* what, uint64_t& total) {
    const uint64_t bytes = uint64_t(count) * sizeof(T);
    total += bytes < 16 ? 16 : bytes;
    return create_filled_buffer(static_cast<const void*>(data), bytes, out, what);
  }
  template <class T>
  Status create_filled_buffer(const std::vector<T>& v, Buffer& out, const char* what, uint64_t& total) {
    return create_filled_buffer(v.data(), v.size(), out, what, total);
  }
  bool direct_uploads() const;  // whether create_filled_buffer writes device memory straight
  // Host -> device and device -> host copies through a staging buffer of at most 64 MiB.
  Status upload(Buffer& dst, const void* data, uint64_t bytes, uint64_t offset = 0);
  Status download(const Buffer& src, void* data, uint64_t bytes, uint64_t offset = 0);
  Status fill_zero(Buffer& dst);

  Status create_pipeline(const uint32_t* spirv, size_t words, uint32_t bindings, uint32_t push_bytes,
                         Pipeline& out, const char* name);
  // The same from a spec; a pipeline create_pipelines_beside made (or is making) from the same
  // spec is taken instead of a new one.
  Status create_pipeline(const PipelineSpec& spec, Pipeline& out);
  // Creates these pipelines on a thread of its own, in order, so that the driver's compile (or its
  // cache's lookup: milliseconds each) runs beside the caller's uploads instead of on its way.
  // Once per context; what nobody takes is destroyed with the context.
  void create_pipelines_beside(std::vector<PipelineSpec> specs);
  size_t pipelines_taken_ahead() const;  // how many create_pipeline took from them

  // Records the dispatches in order, each one's writes visible to the next, submits and waits.
  // `gpu_seconds` (optional) receives each dispatch's time from timestamp queries (0 where the
  // queue has no timestamps).
  Status run(const std::vector<Dispatch>& dispatches, std::vector<double>* gpu_seconds = nullptr);

  // Submits the recording's steps and returns at once; its steps are consumed. Fails when it is
  // still in flight. wait() blocks until it has run (at once when it is not in flight).
  Status submit(Recording& recording);
  Status wait(Recording& recording);

  struct Impl;

 private:
  Context();
  std::unique_ptr<Impl> impl_;
};

}  // namespace gibake::vk
