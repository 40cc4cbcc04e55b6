// Asynchronous submissions: a Recording's steps go into its own command buffer, fence, descriptor
// pool, query pool and host staging, so several can be in flight on the context's one queue.
#include <algorithm>
#include <cstring>

#include "kernels/vulkan/internal.h"

namespace gibake::vk {

namespace {
constexpr uint64_t kFenceTimeoutNs = uint64_t(600) * 1000000000ull;  // as Context::run
constexpr uint64_t kAlign = 256;  // downloads start on this boundary of the readback memory
uint64_t aligned(uint64_t v) { return (v + kAlign - 1) / kAlign * kAlign; }
}  // namespace

struct Recording::Impl {
  enum Kind { kUpload, kDispatch, kDownload };
  struct Step {
    Kind kind;
    size_t index;
  };
  struct Copy {
    const Buffer* buffer;
    uint64_t bytes, offset, at;  // at: where the bytes sit in upload_bytes / the readback memory
  };
  std::vector<Step> steps;
  std::vector<Copy> uploads, downloads;
  std::vector<uint8_t> upload_bytes;
  std::vector<Dispatch> dispatches;
  // Kept from the last submission until the next one (their results and the buffers they name).
  std::vector<Copy> done_downloads;
  std::vector<Dispatch> done_dispatches;
  std::vector<double> seconds;
  double span = 0.0;
  bool in_flight = false;
  uint32_t queries = 0;  // timestamps written by the submission in flight (0: none)

  VkDevice device = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkDescriptorPool dpool = VK_NULL_HANDLE;
  uint32_t dpool_sets = 0, dpool_descriptors = 0;
  VkQueryPool qpool = VK_NULL_HANDLE;
  uint32_t qpool_size = 0;
  std::unique_ptr<Buffer::Impl> staging, readback;

  ~Impl() {
    if (device == VK_NULL_HANDLE) return;
    if (in_flight) vkWaitForFences(device, 1, &fence, VK_TRUE, kFenceTimeoutNs);
    if (qpool != VK_NULL_HANDLE) vkDestroyQueryPool(device, qpool, nullptr);
    if (dpool != VK_NULL_HANDLE) vkDestroyDescriptorPool(device, dpool, nullptr);
    if (fence != VK_NULL_HANDLE) vkDestroyFence(device, fence, nullptr);
    if (pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool, nullptr);  // frees cmd
  }
};

Recording::Recording() : impl_(std::make_unique<Impl>()) {}
Recording::~Recording() = default;
Recording::Recording(Recording&&) noexcept = default;
Recording& Recording::operator=(Recording&&) noexcept = default;

void Recording::upload(Buffer& dst, const void* data, uint64_t bytes, uint64_t offset) {
  Impl& r = *impl_;
  const uint64_t at = aligned(r.upload_bytes.size());
  r.upload_bytes.resize(at + bytes);
  if (bytes) std::memcpy(r.upload_bytes.data() + at, data, bytes);
  r.steps.push_back({Impl::kUpload, r.uploads.size()});
  r.uploads.push_back({&dst, bytes, offset, at});
}

size_t Recording::dispatch(Dispatch d) {
  impl_->steps.push_back({Impl::kDispatch, impl_->dispatches.size()});
  impl_->dispatches.push_back(std::move(d));
  return impl_->dispatches.size() - 1;
}

size_t Recording::download(const Buffer& src, uint64_t bytes, uint64_t offset) {
  Impl& r = *impl_;
  const uint64_t at = r.downloads.empty() ? 0 : aligned(r.downloads.back().at + r.downloads.back().bytes);
  r.steps.push_back({Impl::kDownload, r.downloads.size()});
  r.downloads.push_back({&src, bytes, offset, at});
  return r.downloads.size() - 1;
}

bool Recording::in_flight() const { return impl_->in_flight; }
const void* Recording::result(size_t index) const {
  const Impl& r = *impl_;
  if (r.in_flight || index >= r.done_downloads.size() || !r.readback) return nullptr;
  return static_cast<const uint8_t*>(r.readback->mapped) + r.done_downloads[index].at;
}
const std::vector<double>& Recording::dispatch_seconds() const { return impl_->seconds; }
double Recording::device_seconds() const { return impl_->span; }

namespace {

Status check_copies(const std::vector<Recording::Impl::Copy>& copies, const char* what) {
  for (const auto& c : copies)
    if (!c.buffer || !c.buffer->valid() || c.offset + c.bytes > c.buffer->size())
      return Status::error(ExitCode::RuntimeFailure, "", "vulkan", std::string(what) + " outside the buffer");
  return Status::ok();
}

// The recording's command buffer, fence, descriptor pool (room for its dispatches), query pool and
// host memory, made or grown while it is not in flight.
Status prepare(Context::Impl& im, Recording::Impl& r, uint64_t readback_bytes) {
  if (r.device == VK_NULL_HANDLE) {
    r.device = im.device;
    // A pool of its own: a command pool must not be used from two threads at once, and recordings
    // are recorded on several (the trace's set-up beside relocation's passes, the context's copies).
    auto pi = make<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = im.family;
    GIBAKE_VK(vkCreateCommandPool(im.device, &pi, nullptr, &r.pool));
    auto ci = make<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    ci.commandPool = r.pool;
    ci.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ci.commandBufferCount = 1;
    GIBAKE_VK(vkAllocateCommandBuffers(im.device, &ci, &r.cmd));
    auto fi = make<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    GIBAKE_VK(vkCreateFence(im.device, &fi, nullptr, &r.fence));
  }
  uint32_t descriptors = 0;
  for (const Dispatch& d : r.dispatches) descriptors += std::max<uint32_t>(1, d.pipeline->impl()->bindings);
  const uint32_t sets = uint32_t(r.dispatches.size());
  if (sets > r.dpool_sets || descriptors > r.dpool_descriptors || r.dpool == VK_NULL_HANDLE) {
    if (r.dpool != VK_NULL_HANDLE) vkDestroyDescriptorPool(r.device, r.dpool, nullptr);
    r.dpool = VK_NULL_HANDLE;
    r.dpool_sets = std::max<uint32_t>(sets, 2 * r.dpool_sets);
    r.dpool_descriptors = std::max<uint32_t>(descriptors, 2 * r.dpool_descriptors);
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max<uint32_t>(1, r.dpool_descriptors)};
    auto dpi = make<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    dpi.maxSets = std::max<uint32_t>(1, r.dpool_sets);
    dpi.poolSizeCount = 1;
    dpi.pPoolSizes = &size;
    GIBAKE_VK(vkCreateDescriptorPool(r.device, &dpi, nullptr, &r.dpool));
  } else {
    GIBAKE_VK(vkResetDescriptorPool(r.device, r.dpool, 0));
  }
  r.queries = im.timestamps ? 2 + 2 * sets : 0;
  if (r.queries > r.qpool_size) {
    if (r.qpool != VK_NULL_HANDLE) vkDestroyQueryPool(r.device, r.qpool, nullptr);
    r.qpool = VK_NULL_HANDLE;
    auto qi = make<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = std::max(r.queries, 2 * r.qpool_size);
    GIBAKE_VK(vkCreateQueryPool(r.device, &qi, nullptr, &r.qpool));
    r.qpool_size = qi.queryCount;
  }
  auto grow = [&](std::unique_ptr<Buffer::Impl>& b, uint64_t bytes, bool reading) -> Status {
    if (bytes == 0 || (b && b->size >= bytes)) return Status::ok();
    b.reset();
    auto fresh = std::make_unique<Buffer::Impl>();
    GIBAKE_TRY(im.make_staging(std::max<uint64_t>(bytes, uint64_t(1) << 16), reading, *fresh));
    b = std::move(fresh);
    return Status::ok();
  };
  GIBAKE_TRY(grow(r.staging, r.upload_bytes.size(), false));
  return grow(r.readback, readback_bytes, true);
}

void record_steps(Recording::Impl& r, const DeviceLimits& lim, const std::vector<VkDescriptorSet>& sets) {
  VkCommandBuffer cb = r.cmd;
  const VkQueryPool q = r.queries ? r.qpool : VK_NULL_HANDLE;
  if (q != VK_NULL_HANDLE) {
    vkCmdResetQueryPool(cb, q, 0, r.queries);
    vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, q, 0);
  }
  full_barrier(cb);  // after everything submitted before
  for (const Recording::Impl::Step& s : r.steps) {
    if (s.kind == Recording::Impl::kDispatch) {
      record_dispatch(cb, r.dispatches[s.index], lim, sets[s.index], q, 2 + 2 * uint32_t(s.index));
      continue;
    }
    const bool up = s.kind == Recording::Impl::kUpload;
    const Recording::Impl::Copy& c = up ? r.uploads[s.index] : r.downloads[s.index];
    if (c.bytes == 0) continue;
    if (up) {
      const VkBufferCopy region{c.at, c.offset, c.bytes};
      vkCmdCopyBuffer(cb, r.staging->buffer, c.buffer->impl()->buffer, 1, &region);
    } else {
      const VkBufferCopy region{c.offset, c.at, c.bytes};
      vkCmdCopyBuffer(cb, c.buffer->impl()->buffer, r.readback->buffer, 1, &region);
    }
    full_barrier(cb);
  }
  auto host = make<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                       nullptr);
  if (q != VK_NULL_HANDLE) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, q, 1);
}

}  // namespace

Status Context::submit(Recording& recording) {
  Impl& im = *impl_;
  Recording::Impl& r = *recording.impl_;
  if (r.in_flight) return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "submit of a recording in flight");
  for (const Dispatch& d : r.dispatches) GIBAKE_TRY(check_dispatch(d, im));
  GIBAKE_TRY(check_copies(r.uploads, "recorded upload"));
  GIBAKE_TRY(check_copies(r.downloads, "recorded download"));
  const uint64_t readback = r.downloads.empty() ? 0 : r.downloads.back().at + r.downloads.back().bytes;
  GIBAKE_TRY(prepare(im, r, readback));
  if (!r.upload_bytes.empty()) std::memcpy(r.staging->mapped, r.upload_bytes.data(), r.upload_bytes.size());
  std::vector<VkDescriptorSet> sets;
  GIBAKE_TRY(write_descriptor_sets(im.device, r.dpool, r.dispatches, sets));
  GIBAKE_VK(vkResetCommandBuffer(r.cmd, 0));
  auto begin = make<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  GIBAKE_VK(vkBeginCommandBuffer(r.cmd, &begin));
  record_steps(r, im.lim, sets);
  GIBAKE_VK(vkEndCommandBuffer(r.cmd));
  auto si = make<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  si.commandBufferCount = 1;
  si.pCommandBuffers = &r.cmd;
  {
    std::lock_guard<std::mutex> lock(im.queue_mutex);
    GIBAKE_VK(vkQueueSubmit(im.queue, 1, &si, r.fence));
  }
  r.in_flight = true;
  // The steps are consumed; what their results and timings need is kept until the next submit.
  r.done_downloads = std::move(r.downloads);
  r.done_dispatches = std::move(r.dispatches);
  r.steps.clear();
  r.uploads.clear();
  r.downloads.clear();
  r.dispatches.clear();
  r.upload_bytes.clear();
  return Status::ok();
}

Status Context::wait(Recording& recording) {
  Recording::Impl& r = *recording.impl_;
  if (!r.in_flight) return Status::ok();
  GIBAKE_VK(vkWaitForFences(r.device, 1, &r.fence, VK_TRUE, kFenceTimeoutNs));
  GIBAKE_VK(vkResetFences(r.device, 1, &r.fence));
  r.in_flight = false;
  const size_t n = r.done_dispatches.size();
  r.seconds.assign(n, 0.0);
  r.span = 0.0;
  if (r.queries) {
    std::vector<uint64_t> ticks(r.queries);
    const VkResult q = vkGetQueryPoolResults(r.device, r.qpool, 0, r.queries, ticks.size() * sizeof(uint64_t),
                                             ticks.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT);
    if (q == VK_SUCCESS) {
      const double s = impl_->timestamp_ns * 1e-9;
      r.span = double(ticks[1] - ticks[0]) * s;
      for (size_t i = 0; i < n; ++i) r.seconds[i] = double(ticks[3 + 2 * i] - ticks[2 + 2 * i]) * s;
    }
  }
  return Status::ok();
}

}  // namespace gibake::vk
