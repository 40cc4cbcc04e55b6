// Private to kernels/vulkan: device memory handed out as pieces of a few blocks.
//
// A vkAllocateMemory can cost milliseconds however small the buffer, and a driver may serialise it
// with other threads' calls, so small buffers share blocks (64 MiB of device memory; 4 MiB of
// host-visible memory, whose cost grows with its size); a buffer larger than half a block has its
// own allocation. Freed pieces are reused by later stages; blocks live until destroy(),
// host-visible ones mapped for their whole life. docs/BENCHMARKS.md has the measurements.
#pragma once
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "io/status.h"
#include "kernels/vulkan/context.h"

namespace gibake::vk {

class MemoryPool {
 public:
  struct Piece {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    uint64_t offset = 0;     // where the piece starts in `memory`
    uint64_t size = 0;       // bytes reserved (the request, aligned)
    void* mapped = nullptr;  // the piece's host address, when mapped
    int32_t block = -1;      // index into the pool's blocks; -1: a dedicated allocation
    bool device_local = false;  // of a device-local memory type
  };

  MemoryPool() = default;
  MemoryPool(const MemoryPool&) = delete;
  MemoryPool& operator=(const MemoryPool&) = delete;
  ~MemoryPool();

  void init(VkDevice device, const VkPhysicalDeviceMemoryProperties& properties);
  // `bytes` with `alignment` (a power of two) from memory type `type`; mapped when `map`.
  // Ok with out.memory null only when the device is out of memory (the VkResult in `result`).
  Status allocate(uint32_t type, uint64_t bytes, uint64_t alignment, bool map, Piece& out, VkResult& result);
  // Gives a piece back (its buffer destroyed first). Thread-safe, as allocate() is.
  void release(const Piece& piece);
  // Frees every block; every piece must have been released. Before the device is destroyed.
  void destroy();
  MemoryStats stats() const;

 private:
  // The block size for a memory type: 64 MiB, 4 MiB where the host can see it (at most an eighth of
  // its heap, at least 1 MiB).
  uint64_t block_bytes(uint32_t type) const;
  bool device_local(uint32_t type) const;
  struct Range {
    uint64_t offset, size;
  };
  struct Block {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    uint32_t type = 0;
    uint64_t size = 0;
    void* mapped = nullptr;
    uint32_t pieces = 0;
    std::vector<Range> free;  // sorted by offset, never adjacent
  };
  bool take_range(Block& b, uint64_t bytes, uint64_t alignment, uint64_t& offset);
  // A piece of an existing block of `type` (mapped ones only when `map`); under mutex_.
  bool take_piece(uint32_t type, uint64_t size, uint64_t alignment, bool map, Piece& out);
  VkResult allocate_memory(uint32_t type, uint64_t bytes, bool map, VkDeviceMemory& memory, void*& mapped);

  VkDevice device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties properties_{};
  mutable std::mutex mutex_;
  std::vector<Block> blocks_;
  std::atomic<uint32_t> dedicated_{0};
  std::atomic<uint64_t> device_local_bytes_{0};  // live allocations of device-local types
  std::atomic<uint64_t> allocations_{0};
};

}  // namespace gibake::vk
