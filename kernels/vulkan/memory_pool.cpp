#include "kernels/vulkan/memory_pool.h"

#include <algorithm>

namespace gibake::vk {

namespace {
constexpr uint64_t kDeviceBlockBytes = uint64_t(64) << 20;
constexpr uint64_t kHostBlockBytes = uint64_t(4) << 20;
constexpr uint64_t kMinBlockBytes = uint64_t(1) << 20;
constexpr uint64_t kPieceGranule = 256;  // pieces start and end on it: no slivers between them

uint64_t align_up(uint64_t v, uint64_t a) { return (v + a - 1) & ~(a - 1); }
}  // namespace

MemoryPool::~MemoryPool() { destroy(); }

void MemoryPool::init(VkDevice device, const VkPhysicalDeviceMemoryProperties& properties) {
  device_ = device;
  properties_ = properties;
}

bool MemoryPool::device_local(uint32_t type) const {
  return (properties_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) != 0;
}

uint64_t MemoryPool::block_bytes(uint32_t type) const {
  const VkMemoryType& t = properties_.memoryTypes[type];
  const uint64_t heap = properties_.memoryHeaps[t.heapIndex].size;
  const bool host_visible = (t.propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0;
  const uint64_t want = host_visible ? kHostBlockBytes : kDeviceBlockBytes;
  return std::max(kMinBlockBytes, std::min(want, heap / 8));
}

VkResult MemoryPool::allocate_memory(uint32_t type, uint64_t bytes, bool map, VkDeviceMemory& memory, void*& mapped) {
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = bytes;
  ai.memoryTypeIndex = type;
  memory = VK_NULL_HANDLE;
  mapped = nullptr;
  VkResult r = vkAllocateMemory(device_, &ai, nullptr, &memory);
  if (r != VK_SUCCESS) return r;
  ++allocations_;
  if (device_local(type)) device_local_bytes_ += bytes;
  if (map) {
    r = vkMapMemory(device_, memory, 0, VK_WHOLE_SIZE, 0, &mapped);
    if (r != VK_SUCCESS) {
      vkFreeMemory(device_, memory, nullptr);
      if (device_local(type)) device_local_bytes_ -= bytes;
      memory = VK_NULL_HANDLE;
      mapped = nullptr;
    }
  }
  return r;
}

bool MemoryPool::take_range(Block& b, uint64_t bytes, uint64_t alignment, uint64_t& offset) {
  for (size_t i = 0; i < b.free.size(); ++i) {
    const Range r = b.free[i];
    const uint64_t at = align_up(r.offset, alignment);
    if (at + bytes > r.offset + r.size) continue;
    const Range before{r.offset, at - r.offset}, after{at + bytes, r.offset + r.size - (at + bytes)};
    b.free.erase(b.free.begin() + std::ptrdiff_t(i));
    if (after.size) b.free.insert(b.free.begin() + std::ptrdiff_t(i), after);
    if (before.size) b.free.insert(b.free.begin() + std::ptrdiff_t(i), before);
    offset = at;
    return true;
  }
  return false;
}

bool MemoryPool::take_piece(uint32_t type, uint64_t size, uint64_t alignment, bool map, Piece& out) {
  for (size_t i = 0; i < blocks_.size(); ++i) {
    Block& b = blocks_[i];
    if (b.type != type || (map && !b.mapped) || !take_range(b, size, alignment, out.offset)) continue;
    ++b.pieces;
    out.memory = b.memory;
    out.size = size;
    out.mapped = b.mapped ? static_cast<uint8_t*>(b.mapped) + out.offset : nullptr;
    out.block = int32_t(i);
    return true;
  }
  return false;
}

Status MemoryPool::allocate(uint32_t type, uint64_t bytes, uint64_t alignment, bool map, Piece& out, VkResult& result) {
  out = Piece{};
  result = VK_SUCCESS;
  const uint64_t align = std::max(alignment, kPieceGranule);
  if (align & (align - 1))
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "memory alignment is not a power of two");
  const uint64_t size = align_up(std::max<uint64_t>(bytes, 1), kPieceGranule);
  const uint64_t block_size = block_bytes(type);
  if (size <= block_size / 2) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (take_piece(type, size, align, map, out)) return Status::ok();
    // A new block, mapped when its type is host-visible (its later pieces may want it).
    const bool host_visible = (properties_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0;
    Block b;
    b.type = type;
    b.size = block_size;
    result = allocate_memory(type, block_size, host_visible, b.memory, b.mapped);
    if (result == VK_SUCCESS) {
      b.free.push_back(Range{0, block_size});
      blocks_.push_back(std::move(b));
      take_piece(type, size, align, map, out);  // fits the empty block
      return Status::ok();
    }
    // No room for a whole block: the request alone may still fit.
  }
  // Outside the lock: another thread's small pieces need not wait for a large allocation.
  void* mapped = nullptr;
  result = allocate_memory(type, size, map, out.memory, mapped);
  if (result != VK_SUCCESS) {
    out = Piece{};
    return Status::ok();
  }
  ++dedicated_;
  out.size = size;
  out.device_local = device_local(type);
  out.mapped = mapped;
  out.block = -1;
  return Status::ok();
}

void MemoryPool::release(const Piece& piece) {
  if (piece.memory == VK_NULL_HANDLE) return;
  if (piece.block < 0) {
    vkFreeMemory(device_, piece.memory, nullptr);  // unmaps it too
    --dedicated_;
    if (piece.device_local) device_local_bytes_ -= piece.size;
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  Block& b = blocks_[size_t(piece.block)];
  --b.pieces;
  auto at = std::lower_bound(b.free.begin(), b.free.end(), piece.offset,
                             [](const Range& r, uint64_t offset) { return r.offset < offset; });
  at = b.free.insert(at, Range{piece.offset, piece.size});
  if (at + 1 != b.free.end() && at->offset + at->size == (at + 1)->offset) {  // joins the next range
    at->size += (at + 1)->size;
    b.free.erase(at + 1);
  }
  if (at != b.free.begin() && (at - 1)->offset + (at - 1)->size == at->offset) {  // and the one before
    (at - 1)->size += at->size;
    b.free.erase(at);
  }
}

void MemoryPool::destroy() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Block& b : blocks_)
    if (b.memory != VK_NULL_HANDLE) {
      vkFreeMemory(device_, b.memory, nullptr);
      if (device_local(b.type)) device_local_bytes_ -= b.size;
    }
  blocks_.clear();
}

MemoryStats MemoryPool::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  MemoryStats s;
  s.dedicated = dedicated_;
  s.device_local_bytes = device_local_bytes_;
  s.allocations = allocations_;
  for (const Block& b : blocks_) {
    ++s.blocks;
    s.pieces += b.pieces;
    s.block_bytes += b.size;
  }
  return s;
}

}  // namespace gibake::vk
