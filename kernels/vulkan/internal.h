// Private to kernels/vulkan: the Vulkan handles behind Context, Buffer and Pipeline.
#pragma once
#include <vulkan/vulkan.h>

#include <string>

#include "kernels/vulkan/context.h"

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
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;  // staging buffers only
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

}  // namespace gibake::vk
