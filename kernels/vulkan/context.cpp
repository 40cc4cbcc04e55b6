// The Vulkan compute context: device and queue, buffers and staging copies, pipelines, runs.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>

#include "kernels/vulkan/internal.h"

namespace gibake::vk {

namespace {
constexpr uint64_t kStagingBytes = uint64_t(64) << 20;
// Uploads go through a small reused staging buffer: pinned memory is slow to allocate, so a large
// one made for an upload costs more than the copies it saves (docs/BENCHMARKS.md).
constexpr uint64_t kUploadStagingBytes = uint64_t(8) << 20;
constexpr uint64_t kFenceTimeoutNs = uint64_t(600) * 1000000000ull;  // a run that hangs 10 min is lost
// A copy's writes made visible to the compute shaders of later submissions.
void transfer_to_compute(VkCommandBuffer cb) {
  auto mb = make<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
}
}  // namespace

Buffer::Impl::~Impl() {
  if (buffer != VK_NULL_HANDLE) vkDestroyBuffer(device, buffer, nullptr);
  if (pool) pool->release(memory);  // a block's piece stays mapped with its block
}
Buffer::Buffer() = default;
Buffer::~Buffer() = default;
Buffer::Buffer(Buffer&&) noexcept = default;
Buffer& Buffer::operator=(Buffer&&) noexcept = default;
uint64_t Buffer::size() const { return impl_ ? impl_->size : 0; }

Pipeline::Impl::~Impl() {
  if (pipeline != VK_NULL_HANDLE) vkDestroyPipeline(device, pipeline, nullptr);
  if (layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(device, layout, nullptr);
  if (set_layout != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
}
Pipeline::Pipeline() = default;
Pipeline::~Pipeline() = default;
Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;

Context::Impl::~Impl() {
  if (ahead_thread.joinable()) ahead_thread.join();
  ahead.clear();  // pipelines nobody took, before their device
  if (device != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device);
    if (fence != VK_NULL_HANDLE) vkDestroyFence(device, fence, nullptr);
    if (pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool, nullptr);
    staging.reset();
    readback.reset();
    memory.destroy();
    vkDestroyDevice(device, nullptr);
  }
  inst.destroy();
}

int Context::Impl::memory_type(uint32_t bits, VkMemoryPropertyFlags want) const {
  for (uint32_t i = 0; i < mem.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (mem.memoryTypes[i].propertyFlags & want) == want) return static_cast<int>(i);
  return -1;
}

Status Context::Impl::make_buffer(uint64_t bytes, VkBufferUsageFlags usage, VkMemoryPropertyFlags want, Buffer::Impl& b,
                                  const char* what, int forced_type) {
  b.device = device;
  b.size = bytes;
  auto bi = make<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  bi.size = std::max<uint64_t>(bytes, 16);
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  GIBAKE_VK(vkCreateBuffer(device, &bi, nullptr, &b.buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, b.buffer, &req);
  const int type = forced_type >= 0 && (req.memoryTypeBits & (1u << forced_type))
                       ? forced_type
                       : memory_type(req.memoryTypeBits, want);
  if (type < 0) return Status::error(ExitCode::RuntimeFailure, "", "vulkan", std::string(what) + ": no suitable memory type");
  const bool map = (want & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0;
  VkResult r = VK_SUCCESS;
  GIBAKE_TRY(memory.allocate(static_cast<uint32_t>(type), req.size, req.alignment, map, b.memory, r));
  if (b.memory.memory == VK_NULL_HANDLE)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         std::string(what) + ": cannot allocate " + std::to_string(req.size) + " bytes on " +
                             info.name + " (VkResult " + std::to_string(static_cast<int>(r)) + ")");
  b.pool = &memory;
  GIBAKE_VK(vkBindBufferMemory(device, b.buffer, b.memory.memory, b.memory.offset));
  if (map) b.mapped = b.memory.mapped;
  return Status::ok();
}

Status Context::Impl::make_staging(uint64_t bytes, bool for_reading, Buffer::Impl& b) {
  const VkMemoryPropertyFlags coherent = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkMemoryPropertyFlags flags = coherent;
  if (for_reading && has_memory(coherent | VK_MEMORY_PROPERTY_HOST_CACHED_BIT)) flags |= VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  return make_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, flags, b,
                     "staging buffer");
}

Status Context::Impl::staging_for(uint64_t bytes, bool for_reading, Buffer::Impl*& out) {
  std::unique_ptr<Buffer::Impl>& slot = for_reading ? readback : staging;
  // Uploads go through one buffer of kUploadStagingBytes, made at the first upload; readbacks through
  // one grown to what they ask, up to kStagingBytes.
  const uint64_t want =
      for_reading ? std::max<uint64_t>(std::min(bytes, kStagingBytes), uint64_t(1) << 20) : kUploadStagingBytes;
  if (!slot || slot->size < want) {
    slot.reset();
    auto b = std::make_unique<Buffer::Impl>();
    GIBAKE_TRY(make_staging(want, for_reading, *b));
    slot = std::move(b);
  }
  out = slot.get();
  return Status::ok();
}

bool Context::Impl::has_memory(VkMemoryPropertyFlags want) const {
  for (uint32_t i = 0; i < mem.memoryTypeCount; ++i)
    if ((mem.memoryTypes[i].propertyFlags & want) == want) return true;
  return false;
}

Status Context::Impl::submit(const std::function<void(VkCommandBuffer)>& record) {
  GIBAKE_VK(vkResetCommandBuffer(cmd, 0));
  auto begin = make<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  GIBAKE_VK(vkBeginCommandBuffer(cmd, &begin));
  full_barrier(cmd);  // after any Recording still in flight on the queue
  record(cmd);
  GIBAKE_VK(vkEndCommandBuffer(cmd));
  auto si = make<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  GIBAKE_VK(vkQueueSubmit(queue, 1, &si, fence));
  GIBAKE_VK(vkWaitForFences(device, 1, &fence, VK_TRUE, kFenceTimeoutNs));
  GIBAKE_VK(vkResetFences(device, 1, &fence));
  return Status::ok();
}

Status Context::Impl::create_device(uint32_t index, bool allow_float64) {
  uint32_t n = 0;
  GIBAKE_VK(vkEnumeratePhysicalDevices(inst.instance, &n, nullptr));
  std::vector<VkPhysicalDevice> devices(n);
  GIBAKE_VK(vkEnumeratePhysicalDevices(inst.instance, &n, devices.data()));
  if (index >= n)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         "no Vulkan device " + std::to_string(index) + " (" + std::to_string(n) + " found)");
  phys = devices[index];
  info = describe_device(phys, index);
  vkGetPhysicalDeviceMemoryProperties(phys, &mem);
  uint64_t device_heap = 0;
  for (uint32_t h = 0; h < mem.memoryHeapCount; ++h)
    if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      device_heap = std::max<uint64_t>(device_heap, mem.memoryHeaps[h].size);
  const VkMemoryPropertyFlags direct =
      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  for (uint32_t t = 0; t < mem.memoryTypeCount && direct_type < 0; ++t)
    if ((mem.memoryTypes[t].propertyFlags & direct) == direct &&
        mem.memoryHeaps[mem.memoryTypes[t].heapIndex].size >= device_heap)  // not a 256 MiB BAR window
      direct_type = static_cast<int>(t);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(phys, &props);
  limits = props.limits;
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(phys, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(phys, &nq, families.data());
  int chosen = -1;
  for (uint32_t f = 0; f < nq && chosen < 0; ++f)
    if (families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) chosen = static_cast<int>(f);
  if (chosen < 0)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", info.name + " has no compute queue");
  family = static_cast<uint32_t>(chosen);
  timestamps = families[family].timestampValidBits > 0 && limits.timestampPeriod > 0.f;
  timestamp_ns = limits.timestampPeriod;
  const float priority = 1.f;
  auto qi = make<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  qi.queueFamilyIndex = family;
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkPhysicalDeviceFeatures have;
  vkGetPhysicalDeviceFeatures(phys, &have);
  VkPhysicalDeviceFeatures features{};
  features.shaderInt64 = have.shaderInt64;  // counter-based RNG keys are 64-bit
  // Doubles: per-probe luminance statistics (Welford) and relocation sums, in the CPU's precision.
  features.shaderFloat64 = allow_float64 ? have.shaderFloat64 : VK_FALSE;
  float64 = features.shaderFloat64 == VK_TRUE;
  auto di = make<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  di.queueCreateInfoCount = 1;
  di.pQueueCreateInfos = &qi;
  di.pEnabledFeatures = &features;
  GIBAKE_VK(vkCreateDevice(phys, &di, nullptr, &device));
  memory.init(device, mem);
  vkGetDeviceQueue(device, family, 0, &queue);
  auto pi = make<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pi.queueFamilyIndex = family;
  GIBAKE_VK(vkCreateCommandPool(device, &pi, nullptr, &pool));
  auto ci = make<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  ci.commandPool = pool;
  ci.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ci.commandBufferCount = 1;
  GIBAKE_VK(vkAllocateCommandBuffers(device, &ci, &cmd));
  auto fi = make<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  GIBAKE_VK(vkCreateFence(device, &fi, nullptr, &fence));
  return Status::ok();
}
void Context::Impl::read_limits(uint32_t max_groups, uint64_t forced_memory) {
  auto m3 = make<VkPhysicalDeviceMaintenance3Properties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES);
  auto p2 = make<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
  p2.pNext = &m3;
  vkGetPhysicalDeviceProperties2(phys, &p2);
  for (int i = 0; i < 3; ++i) lim.group_count[i] = limits.maxComputeWorkGroupCount[i];
  if (max_groups) lim.group_count[0] = std::min(max_groups, lim.group_count[0]);
  lim.storage_buffer_range = limits.maxStorageBufferRange;
  // 0 where the driver leaves the structure unfilled: then only the storage range binds.
  lim.memory_allocation = m3.maxMemoryAllocationSize ? m3.maxMemoryAllocationSize : UINT64_MAX;
  lim.shared_memory = limits.maxComputeSharedMemorySize;
  lim.storage_buffers = std::min(limits.maxPerStageDescriptorStorageBuffers, limits.maxDescriptorSetStorageBuffers);
  lim.device_memory = info.device_memory;
  lim.device_memory_source = "device-local heap";
  const uint64_t budget = device_memory_budget();
  if (budget > 0 && budget < lim.device_memory) {
    lim.device_memory = budget;
    lim.device_memory_source = "memory budget (VK_EXT_memory_budget)";
  }
  if (forced_memory > 0 && forced_memory < lim.device_memory) {
    lim.device_memory = forced_memory;
    lim.device_memory_source = "test limit";
  }
}

// The budget VK_EXT_memory_budget gives this process in the largest device-local heap (other
// processes' allocations taken off); 0 where the device lacks the extension.
uint64_t Context::Impl::device_memory_budget() const {
  uint32_t n = 0;
  if (vkEnumerateDeviceExtensionProperties(phys, nullptr, &n, nullptr) != VK_SUCCESS) return 0;
  std::vector<VkExtensionProperties> extensions(n);
  if (vkEnumerateDeviceExtensionProperties(phys, nullptr, &n, extensions.data()) != VK_SUCCESS) return 0;
  const bool has = std::any_of(extensions.begin(), extensions.end(), [](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) == 0;
  });
  if (!has) return 0;
  auto budget = make<VkPhysicalDeviceMemoryBudgetPropertiesEXT>(
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT);
  auto m2 = make<VkPhysicalDeviceMemoryProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2);
  m2.pNext = &budget;
  vkGetPhysicalDeviceMemoryProperties2(phys, &m2);
  uint64_t heap = 0, out = 0;
  for (uint32_t h = 0; h < m2.memoryProperties.memoryHeapCount; ++h) {
    const VkMemoryHeap& mh = m2.memoryProperties.memoryHeaps[h];
    if ((mh.flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) && mh.size > heap) heap = mh.size, out = budget.heapBudget[h];
  }
  return out;
}

Context::Context() : impl_(std::make_unique<Impl>()) {}
Context::~Context() = default;

Status Context::create(const ContextOptions& options, std::unique_ptr<Context>& out) {
  std::unique_ptr<Context> c(new Context());
  Impl& im = *c->impl_;
  GIBAKE_TRY(create_instance(options.validation, &im.errors, &im.first_error, im.inst));
  GIBAKE_TRY(im.create_device(options.device_index, options.float64));
  im.read_limits(options.max_group_count, options.device_memory);
  out = std::move(c);
  return Status::ok();
}

Status Context::create_chosen(const ContextOptions& options, const DeviceChooser& choose,
                              std::unique_ptr<Context>& out) {
  out.reset();
  std::unique_ptr<Context> c(new Context());
  Impl& im = *c->impl_;
  std::vector<DeviceInfo> devices;
  uint32_t index = 0;
  // No ICD at all is "no devices", as in list_devices.
  if (!create_instance(options.validation, &im.errors, &im.first_error, im.inst)) {
    choose(devices, index);
    return Status::ok();
  }
  uint32_t n = 0;
  VkResult r = vkEnumeratePhysicalDevices(im.inst.instance, &n, nullptr);
  std::vector<VkPhysicalDevice> handles(n);
  if (r == VK_SUCCESS && n > 0) r = vkEnumeratePhysicalDevices(im.inst.instance, &n, handles.data());
  if (r == VK_SUCCESS || r == VK_INCOMPLETE)
    for (uint32_t i = 0; i < n; ++i) devices.push_back(describe_device(handles[i], i));
  if (!choose(devices, index)) return Status::ok();
  GIBAKE_TRY(im.create_device(index, options.float64));
  im.read_limits(options.max_group_count, options.device_memory);
  out = std::move(c);
  return Status::ok();
}

const DeviceInfo& Context::device() const { return impl_->info; }
bool Context::validation_enabled() const { return impl_->inst.validation; }
bool Context::shader_float64() const { return impl_->float64; }
uint32_t Context::validation_errors() const { return impl_->errors; }
std::string Context::first_validation_error() const { return impl_->first_error; }

MemoryStats Context::memory_stats() const { return impl_->memory.stats(); }

uint64_t Context::max_buffer_bytes() const {
  const DeviceLimits& l = impl_->lim;
  return std::min({l.storage_buffer_range, l.memory_allocation, l.device_memory});
}

uint64_t Context::device_memory() const { return impl_->lim.device_memory; }
uint64_t Context::device_bytes() const { return impl_->memory.stats().device_local_bytes; }

Status Context::check_device_memory(uint64_t need, uint64_t held, const std::string& what,
                                    const std::string& lowers) const {
  const DeviceLimits& l = impl_->lim;
  if (need <= l.device_memory && held <= l.device_memory - need) return Status::ok();
  // Whole KiB under a MiB, whole MiB above (rounded up: a figure never reads as fitting when it does not).
  const auto mib = [](uint64_t bytes) {
    if (bytes < (uint64_t(1) << 20)) return std::to_string((bytes + 1023) >> 10) + " KiB";
    return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MiB";
  };
  return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                       what + " needs about " + mib(need) + " of device memory" +
                           (held ? " beside the " + mib(held) + " the bake holds there" : std::string()) + "; " +
                           impl_->info.name + " has " + mib(l.device_memory) + " (" + l.device_memory_source +
                           "); " + lowers);
}

const DeviceLimits& Context::limits() const { return impl_->lim; }

Status Context::create_buffer(uint64_t bytes, Buffer& out, const char* what) {
  if (bytes > max_buffer_bytes()) {
    const DeviceLimits& l = impl_->lim;
    const char* limit = bytes > l.storage_buffer_range ? "maxStorageBufferRange"
                        : bytes > l.memory_allocation  ? "maxMemoryAllocationSize"
                                                       : "its device memory";
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         std::string(what) + " needs " + std::to_string(bytes) + " bytes in one buffer; " +
                             impl_->info.name + " allows " + std::to_string(max_buffer_bytes()) + " (" + limit +
                             ")");
  }
  auto b = std::make_unique<Buffer::Impl>();
  GIBAKE_TRY(impl_->make_buffer(bytes,
                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, *b, what));
  out.impl_ = std::move(b);
  return Status::ok();
}

namespace {

// Large copies into (or out of) the mapped staging memory go side by side in the calling arena (the
// set-up uploads a textured scene's texture pool, ~10^8 bytes, through here while the device
// waits). Isolated, so that a thread waiting here never picks up an unrelated task of the arena
// while the queue's mutex is held.
void staging_copy(void* to, const void* from, uint64_t bytes) {
  constexpr uint64_t kPiece = uint64_t(1) << 20;
  if (bytes < 8 * kPiece) {
    std::memcpy(to, from, bytes);
    return;
  }
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(
        tbb::blocked_range<uint64_t>(0, (bytes + kPiece - 1) / kPiece), [&](const tbb::blocked_range<uint64_t>& r) {
          const uint64_t first = r.begin() * kPiece, last = std::min(bytes, r.end() * kPiece);
          std::memcpy(static_cast<uint8_t*>(to) + first, static_cast<const uint8_t*>(from) + first, last - first);
        });
  });
}

}  // namespace

Status Context::upload(Buffer& dst, const void* data, uint64_t bytes, uint64_t offset) {
  if (!dst.impl_ || offset + bytes > dst.impl_->size)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "upload outside the buffer");
  if (bytes == 0) return Status::ok();
  std::lock_guard<std::mutex> lock(impl_->queue_mutex);
  Buffer::Impl* staging = nullptr;
  GIBAKE_TRY(impl_->staging_for(bytes, false, staging));
  for (uint64_t done = 0; done < bytes;) {
    const uint64_t n = std::min(staging->size, bytes - done);
    staging_copy(staging->mapped, static_cast<const uint8_t*>(data) + done, n);
    const VkBufferCopy region{0, offset + done, n};
    GIBAKE_TRY(impl_->submit([&](VkCommandBuffer cb) {
      vkCmdCopyBuffer(cb, staging->buffer, dst.impl_->buffer, 1, &region);
      transfer_to_compute(cb);
    }));
    done += n;
  }
  return Status::ok();
}

bool Context::direct_uploads() const { return impl_->direct_type >= 0; }

Status Context::create_filled_buffer(const void* data, uint64_t bytes, Buffer& out, const char* what) {
  if (impl_->direct_type >= 0 && bytes <= max_buffer_bytes()) {
    auto b = std::make_unique<Buffer::Impl>();
    const VkMemoryPropertyFlags flags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                        VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const Status made = impl_->make_buffer(
        std::max<uint64_t>(bytes, 16),
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, flags,
        *b, what, impl_->direct_type);
    if (made && b->mapped) {  // else (that memory full): the staged route below
      staging_copy(b->mapped, data, bytes);
      b->mapped = nullptr;  // not a staging buffer (its memory stays mapped until freed)
      out.impl_ = std::move(b);
      return Status::ok();
    }
  }
  GIBAKE_TRY(create_buffer(std::max<uint64_t>(bytes, 16), out, what));
  return upload(out, data, bytes);
}

Status Context::download(const Buffer& src, void* data, uint64_t bytes, uint64_t offset) {
  if (!src.impl_ || offset + bytes > src.impl_->size)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "download outside the buffer");
  if (bytes == 0) return Status::ok();
  std::lock_guard<std::mutex> lock(impl_->queue_mutex);
  Buffer::Impl* staging = nullptr;
  GIBAKE_TRY(impl_->staging_for(bytes, true, staging));
  for (uint64_t done = 0; done < bytes;) {
    const uint64_t n = std::min(staging->size, bytes - done);
    const VkBufferCopy region{offset + done, 0, n};
    GIBAKE_TRY(impl_->submit([&](VkCommandBuffer cb) { vkCmdCopyBuffer(cb, src.impl_->buffer, staging->buffer, 1, &region); }));
    staging_copy(static_cast<uint8_t*>(data) + done, staging->mapped, n);
    done += n;
  }
  return Status::ok();
}

Status Context::fill_zero(Buffer& dst) {
  if (!dst.impl_) return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "fill of an empty buffer");
  VkBuffer b = dst.impl_->buffer;
  std::lock_guard<std::mutex> lock(impl_->queue_mutex);
  return impl_->submit([&](VkCommandBuffer cb) {
    vkCmdFillBuffer(cb, b, 0, VK_WHOLE_SIZE, 0);
    transfer_to_compute(cb);
  });
}

namespace {

// A pipeline from `spec` on `device`: what create_pipeline and the thread of create_pipelines_beside make.
Status make_pipeline(VkDevice device, const PipelineSpec& spec, std::unique_ptr<Pipeline::Impl>& out) {
  auto p = std::make_unique<Pipeline::Impl>();
  p->device = device;
  p->bindings = spec.bindings;
  p->push_bytes = spec.push_bytes;
  p->name = spec.name;
  std::vector<VkDescriptorSetLayoutBinding> b(spec.bindings);
  for (uint32_t i = 0; i < spec.bindings; ++i) {
    b[i].binding = i;
    b[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    b[i].descriptorCount = 1;
    b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  auto li = make<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  li.bindingCount = spec.bindings;
  li.pBindings = b.data();
  GIBAKE_VK(vkCreateDescriptorSetLayout(device, &li, nullptr, &p->set_layout));
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, spec.push_bytes};
  auto pl = make<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &p->set_layout;
  pl.pushConstantRangeCount = spec.push_bytes ? 1 : 0;
  pl.pPushConstantRanges = &range;
  GIBAKE_VK(vkCreatePipelineLayout(device, &pl, nullptr, &p->layout));
  auto mi = make<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  mi.codeSize = spec.words * sizeof(uint32_t);
  mi.pCode = spec.spirv;
  VkShaderModule module = VK_NULL_HANDLE;
  GIBAKE_VK(vkCreateShaderModule(device, &mi, nullptr, &module));
  auto ci = make<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module;
  ci.stage.pName = "main";
  ci.layout = p->layout;
  const VkResult r = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &p->pipeline);
  vkDestroyShaderModule(device, module, nullptr);
  if (r != VK_SUCCESS) return vk_error((std::string("vkCreateComputePipelines ") + spec.name).c_str(), r);
  out = std::move(p);
  return Status::ok();
}

// A kernel binding more storage buffers than the device allows is refused before it is made.
Status check_bindings(const DeviceInfo& info, const DeviceLimits& lim, uint32_t bindings, const char* name) {
  if (bindings <= lim.storage_buffers) return Status::ok();
  return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                       std::string(name ? name : "a kernel") + " binds " + std::to_string(bindings) +
                           " storage buffers; " + info.name + " allows " + std::to_string(lim.storage_buffers) +
                           " (maxPerStageDescriptorStorageBuffers, maxDescriptorSetStorageBuffers)");
}

}  // namespace

Status Context::create_pipeline(const uint32_t* spirv, size_t words, uint32_t bindings, uint32_t push_bytes,
                                Pipeline& out, const char* name) {
  GIBAKE_TRY(check_bindings(impl_->info, impl_->lim, bindings, name));
  std::unique_ptr<Pipeline::Impl> p;
  GIBAKE_TRY(make_pipeline(impl_->device, PipelineSpec{spirv, words, bindings, push_bytes, name, 0}, p));
  out.impl_ = std::move(p);
  return Status::ok();
}

namespace {

bool same_spec(const PipelineSpec& a, const PipelineSpec& b) {
  return a.spirv == b.spirv && a.words == b.words && a.bindings == b.bindings && a.push_bytes == b.push_bytes;
}

}  // namespace

Status Context::create_pipeline(const PipelineSpec& spec, Pipeline& out) {
  Impl& im = *impl_;
  GIBAKE_TRY(check_bindings(im.info, im.lim, spec.bindings, spec.name));
  if (spec.shared_bytes > im.lim.shared_memory)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         std::string(spec.name) + " needs " + std::to_string(spec.shared_bytes) +
                             " bytes of shared memory; " + im.info.name + " allows " +
                             std::to_string(im.lim.shared_memory) + " (maxComputeSharedMemorySize)");
  {
    std::unique_lock<std::mutex> lock(im.ahead_mutex);
    for (size_t i = 0; i < im.ahead.size(); ++i) {
      Impl::Ahead& a = im.ahead[i];
      if (a.taken || !same_spec(a.spec, spec)) continue;
      a.taken = true;
      im.ahead_done.wait(lock, [&] { return im.ahead_made > i; });
      if (!a.status) break;  // made again below, which reports the error
      out.impl_ = std::move(a.pipeline);
      ++im.ahead_taken;
      return Status::ok();
    }
  }
  return create_pipeline(spec.spirv, spec.words, spec.bindings, spec.push_bytes, out, spec.name);
}

size_t Context::pipelines_taken_ahead() const {
  std::lock_guard<std::mutex> lock(impl_->ahead_mutex);
  return impl_->ahead_taken;
}

void Context::create_pipelines_beside(std::vector<PipelineSpec> specs) {
  Impl& im = *impl_;
  if (im.ahead_thread.joinable() || specs.empty()) return;
  {
    std::lock_guard<std::mutex> lock(im.ahead_mutex);
    for (const PipelineSpec& spec : specs) im.ahead.push_back({spec, nullptr, Status::ok(), false});
  }
  // The entries are never added to or removed while the thread runs: it reaches each by index.
  im.ahead_thread = std::thread([&im] {
    for (size_t i = 0; i < im.ahead.size(); ++i) {
      std::unique_ptr<Pipeline::Impl> made;
      Status st = check_bindings(im.info, im.lim, im.ahead[i].spec.bindings, im.ahead[i].spec.name);
      if (st) st = make_pipeline(im.device, im.ahead[i].spec, made);
      std::lock_guard<std::mutex> lock(im.ahead_mutex);
      im.ahead[i].status = st;
      im.ahead[i].pipeline = std::move(made);
      im.ahead_made = i + 1;
      im.ahead_done.notify_all();
    }
  });
}

void dispatch_grid(const Dispatch& d, const DeviceLimits& lim, uint32_t out[3]) {
  if (!d.flat_groups) {
    for (int i = 0; i < 3; ++i) out[i] = d.groups[i];
    return;
  }
  const uint64_t x = std::min<uint64_t>(d.flat_groups, lim.group_count[0]);
  const uint64_t y = (d.flat_groups + x - 1) / x;
  out[0] = uint32_t(x);
  out[1] = uint32_t(std::min<uint64_t>(y, UINT32_MAX));
  out[2] = 1;
}

Status check_dispatch(const Dispatch& d, const Context::Impl& im) {
  if (!d.pipeline || !d.pipeline->impl() || d.buffers.size() != d.pipeline->impl()->bindings ||
      d.push.size() != d.pipeline->impl()->push_bytes)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "dispatch does not match its pipeline");
  for (const Buffer* b : d.buffers)
    if (!b || !b->valid()) return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "dispatch with an empty buffer");
  uint32_t grid[3];
  dispatch_grid(d, im.lim, grid);
  for (int i = 0; i < 3; ++i)
    if (grid[i] > im.lim.group_count[i])
      return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                           d.pipeline->impl()->name + " dispatches " + std::to_string(grid[i]) + " workgroups in " +
                               "xyz"[i] + "; " + im.info.name + " allows " + std::to_string(im.lim.group_count[i]) +
                               " (maxComputeWorkGroupCount)");
  return Status::ok();
}

Status write_descriptor_sets(VkDevice device, VkDescriptorPool dpool, const std::vector<Dispatch>& dispatches,
                             std::vector<VkDescriptorSet>& sets) {
  sets.assign(dispatches.size(), VK_NULL_HANDLE);
  for (size_t i = 0; i < dispatches.size(); ++i) {
    auto ai = make<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    ai.descriptorPool = dpool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &dispatches[i].pipeline->impl()->set_layout;
    GIBAKE_VK(vkAllocateDescriptorSets(device, &ai, &sets[i]));
    std::vector<VkDescriptorBufferInfo> infos(dispatches[i].buffers.size());
    std::vector<VkWriteDescriptorSet> writes(infos.size());
    for (size_t k = 0; k < infos.size(); ++k) {
      infos[k] = {dispatches[i].buffers[k]->impl()->buffer, 0, VK_WHOLE_SIZE};
      writes[k] = make<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
      writes[k].dstSet = sets[i];
      writes[k].dstBinding = static_cast<uint32_t>(k);
      writes[k].descriptorCount = 1;
      writes[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[k].pBufferInfo = &infos[k];
    }
    vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  }
  return Status::ok();
}

void record_dispatch(VkCommandBuffer cb, const Dispatch& d, const DeviceLimits& lim, VkDescriptorSet set,
                     VkQueryPool qpool, uint32_t query) {
  const Pipeline::Impl& p = *d.pipeline->impl();
  uint32_t grid[3];
  dispatch_grid(d, lim, grid);
  if (qpool != VK_NULL_HANDLE) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, qpool, query);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &set, 0, nullptr);
  if (p.push_bytes) vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, p.push_bytes, d.push.data());
  vkCmdDispatch(cb, grid[0], grid[1], grid[2]);
  if (qpool != VK_NULL_HANDLE) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, qpool, query + 1);
  // Each dispatch sees the previous one's writes; the last one's are visible to copies.
  auto mb = make<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
}

void full_barrier(VkCommandBuffer cb) {
  auto mb = make<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                     VK_ACCESS_TRANSFER_WRITE_BIT;
  const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  vkCmdPipelineBarrier(cb, stages, stages, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

Status Context::run(const std::vector<Dispatch>& dispatches, std::vector<double>* gpu_seconds) {
  Impl& im = *impl_;
  const uint32_t n = static_cast<uint32_t>(dispatches.size());
  if (gpu_seconds) gpu_seconds->assign(n, 0.0);
  if (n == 0) return Status::ok();
  uint32_t descriptors = 0;
  for (const Dispatch& d : dispatches) {
    GIBAKE_TRY(check_dispatch(d, im));
    descriptors += std::max<uint32_t>(1, d.pipeline->impl()->bindings);
  }
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, descriptors};
  auto dpi = make<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  dpi.maxSets = n;
  dpi.poolSizeCount = 1;
  dpi.pPoolSizes = &size;
  VkDescriptorPool dpool = VK_NULL_HANDLE;
  GIBAKE_VK(vkCreateDescriptorPool(im.device, &dpi, nullptr, &dpool));
  VkQueryPool qpool = VK_NULL_HANDLE;
  const bool timed = gpu_seconds && im.timestamps;
  VkResult qr = VK_SUCCESS;
  if (timed) {
    auto qi = make<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2 * n;
    qr = vkCreateQueryPool(im.device, &qi, nullptr, &qpool);
  }
  auto cleanup = [&] {
    if (qpool != VK_NULL_HANDLE) vkDestroyQueryPool(im.device, qpool, nullptr);
    vkDestroyDescriptorPool(im.device, dpool, nullptr);
  };
  if (qr != VK_SUCCESS) {
    cleanup();
    return vk_error("vkCreateQueryPool", qr);
  }
  std::vector<VkDescriptorSet> sets;
  Status st = write_descriptor_sets(im.device, dpool, dispatches, sets);
  std::unique_lock<std::mutex> lock(im.queue_mutex);
  if (st)
    st = im.submit([&](VkCommandBuffer cb) {
      if (timed) vkCmdResetQueryPool(cb, qpool, 0, 2 * n);
      for (uint32_t i = 0; i < n; ++i) record_dispatch(cb, dispatches[i], im.lim, sets[i], qpool, 2 * i);
    });
  if (st && timed) {
    std::vector<uint64_t> ticks(2 * n);
    const VkResult r = vkGetQueryPoolResults(im.device, qpool, 0, 2 * n, ticks.size() * sizeof(uint64_t), ticks.data(),
                                             sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    if (r == VK_SUCCESS)
      for (uint32_t i = 0; i < n; ++i)
        (*gpu_seconds)[i] = double(ticks[2 * i + 1] - ticks[2 * i]) * im.timestamp_ns * 1e-9;
  }
  cleanup();
  return st;
}

}  // namespace gibake::vk
