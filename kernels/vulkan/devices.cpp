// Instance creation (with the validation layer when asked and installed) and device listing.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <vector>

#include "kernels/vulkan/internal.h"

namespace gibake::vk {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool has_layer(const char* name) {
  uint32_t n = 0;
  if (vkEnumerateInstanceLayerProperties(&n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(n);
  if (vkEnumerateInstanceLayerProperties(&n, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT, const VkDebugUtilsMessengerCallbackDataEXT* data,
                                          void* user) {
  auto* inst = static_cast<Instance*>(user);
  if ((severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) && inst->error_count) {
    if (*inst->error_count == 0 && inst->first_error && data && data->pMessage) *inst->first_error = data->pMessage;
    ++*inst->error_count;
  }
  return VK_FALSE;
}

std::string type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

std::string version_text(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

}  // namespace

Status vk_error(const char* call, VkResult r) {
  std::string what = std::string(call) + " failed (VkResult " + std::to_string(static_cast<int>(r)) + ")";
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY) what += ": out of memory";
  if (r == VK_ERROR_DEVICE_LOST) what += ": device lost";
  return Status::error(ExitCode::RuntimeFailure, "", "vulkan", what);
}

bool DeviceInfo::is_lavapipe() const {
  std::string lower = name + " " + driver;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return type == "cpu" && (lower.find("llvmpipe") != std::string::npos || lower.find("lavapipe") != std::string::npos);
}

void Instance::destroy() {
  if (messenger != VK_NULL_HANDLE) {
    auto destroy_fn = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy_fn) destroy_fn(instance, messenger, nullptr);
    messenger = VK_NULL_HANDLE;
  }
  if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
  instance = VK_NULL_HANDLE;
}

Status create_instance(bool validation, uint32_t* error_count, std::string* first_error, Instance& out) {
  out.validation = validation && has_layer(kValidationLayer);
  out.error_count = error_count;
  out.first_error = first_error;
  auto app = make<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "gibake";
  app.apiVersion = VK_API_VERSION_1_1;
  auto info = make<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pApplicationInfo = &app;
  const char* layers[] = {kValidationLayer};
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  auto dbg = make<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  dbg.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dbg.pfnUserCallback = on_message;
  dbg.pUserData = &out;
  if (out.validation) {
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = layers;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
  }
  GIBAKE_VK(vkCreateInstance(&info, nullptr, &out.instance));
  if (out.validation) {
    auto create_fn = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(out.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create_fn) GIBAKE_VK(create_fn(out.instance, &dbg, nullptr, &out.messenger));
  }
  return Status::ok();
}

DeviceInfo describe_device(VkPhysicalDevice device, uint32_t index) {
  DeviceInfo d;
  d.index = index;
  auto driver = make<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
  auto props = make<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
  VkPhysicalDeviceProperties base;
  vkGetPhysicalDeviceProperties(device, &base);
  // Driver properties are core from Vulkan 1.2 (every device gibake meets: lavapipe, NVIDIA).
  if (base.apiVersion >= VK_API_VERSION_1_2) props.pNext = &driver;
  vkGetPhysicalDeviceProperties2(device, &props);
  d.name = props.properties.deviceName;
  d.type = type_name(props.properties.deviceType);
  d.api = version_text(props.properties.apiVersion);
  d.driver = driver.driverName[0] ? std::string(driver.driverName) : "driver " + std::to_string(props.properties.driverVersion);
  if (driver.driverInfo[0]) d.driver += std::string(" ") + driver.driverInfo;
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(device, &mem);
  for (uint32_t h = 0; h < mem.memoryHeapCount; ++h)
    if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      d.device_memory = std::max<uint64_t>(d.device_memory, mem.memoryHeaps[h].size);
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &nq, families.data());
  for (const auto& f : families)
    if (f.queueFlags & VK_QUEUE_COMPUTE_BIT) d.compute = true;
  return d;
}

Status list_devices(std::vector<DeviceInfo>& out) {
  out.clear();
  Instance inst;
  const Status st = create_instance(false, nullptr, nullptr, inst);
  // No ICD at all is "no devices", not an error: the CPU backend still works.
  if (!st) return Status::ok();
  uint32_t n = 0;
  VkResult r = vkEnumeratePhysicalDevices(inst.instance, &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  if (r == VK_SUCCESS && n > 0) r = vkEnumeratePhysicalDevices(inst.instance, &n, devices.data());
  if (r != VK_SUCCESS && r != VK_INCOMPLETE) {
    inst.destroy();
    return vk_error("vkEnumeratePhysicalDevices", r);
  }
  for (uint32_t i = 0; i < n; ++i) out.push_back(describe_device(devices[i], i));
  inst.destroy();
  return Status::ok();
}

}  // namespace gibake::vk
