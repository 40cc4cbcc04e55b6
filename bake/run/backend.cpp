#include "bake/run/backend.h"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <ostream>
#include <thread>

namespace gibake {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() < 9 && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

Status no_device(const std::string& what) {
  return Status::error(ExitCode::RuntimeFailure, "", "--backend vulkan", what);
}

std::string device_list(const std::vector<vk::DeviceInfo>& devices) {
  if (devices.empty()) return "the Vulkan loader found no device";
  std::string s = "devices:";
  for (const auto& d : devices) s += " [" + std::to_string(d.index) + "] " + d.name + " (" + d.type + ")";
  return s;
}

// The device --vulkan-device names, or null with `why` set.
const vk::DeviceInfo* find_named(const std::string& name, const std::vector<vk::DeviceInfo>& devices,
                                 std::string& why) {
  const std::string want = lower(name);
  for (const auto& d : devices) {
    if (!d.compute) continue;
    if (all_digits(want)     ? d.index == std::stoul(want)
        : want == "lavapipe" ? d.is_lavapipe()
                             : lower(d.name).find(want) != std::string::npos)
      return &d;
  }
  why = "no usable Vulkan device matches --vulkan-device '" + name + "'; " + device_list(devices);
  return nullptr;
}

// The automatic pick: the first discrete GPU, else the first integrated one (never a CPU device).
const vk::DeviceInfo* find_gpu(const std::vector<vk::DeviceInfo>& devices) {
  for (const char* type : {"discrete", "integrated"})
    for (const auto& d : devices)
      if (d.compute && d.type == type) return &d;
  return nullptr;
}

}  // namespace

const char* backend_name(Backend b) {
  switch (b) {
    case Backend::Auto:
      return "auto";
    case Backend::Cpu:
      return "cpu";
    case Backend::Vulkan:
      return "vulkan";
  }
  return "?";
}

bool parse_backend(const std::string& text, Backend& out) {
  if (text == "auto")
    out = Backend::Auto;
  else if (text == "cpu")
    out = Backend::Cpu;
  else if (text == "vulkan")
    out = Backend::Vulkan;
  else
    return false;
  return true;
}

const vk::DeviceInfo* auto_candidate(const BackendSettings& s, const std::vector<vk::DeviceInfo>& devices) {
  std::string why;
  if (!s.vulkan_device.empty()) return find_named(s.vulkan_device, devices, why);
  if (const vk::DeviceInfo* gpu = find_gpu(devices)) return gpu;
  for (const auto& d : devices)  // a CPU device, so that the reason names it
    if (d.compute) return &d;
  return nullptr;
}

GpuKind gpu_kind(const vk::DeviceInfo* d, bool cpu_device_as_gpu) {
  if (!d) return GpuKind::None;
  if (cpu_device_as_gpu) return GpuKind::Discrete;
  if (d->type == "discrete") return GpuKind::Discrete;
  if (d->type == "integrated") return GpuKind::Integrated;
  return GpuKind::CpuDevice;  // cpu, virtual, other: weighed as the CPU it probably is
}

Status choose_backend(const BackendSettings& s, const std::vector<vk::DeviceInfo>& devices, BackendChoice& out) {
  out = BackendChoice{};
  if (s.backend == Backend::Cpu) return Status::ok();
  if (s.backend == Backend::Auto) {
    const vk::DeviceInfo* d = auto_candidate(s, devices);
    out.automatic = true;
    out.decision = decide_auto(s.workload, gpu_kind(d, s.auto_cpu_device_as_gpu));
    if (out.decision.vulkan) {
      out.backend = Backend::Vulkan;
      out.device = *d;
    }
    return Status::ok();
  }
  std::string why;
  const vk::DeviceInfo* d = s.vulkan_device.empty() ? find_gpu(devices) : find_named(s.vulkan_device, devices, why);
  if (!d && s.vulkan_device.empty())
    why =
        "no Vulkan GPU (discrete or integrated) found; name a device with --vulkan-device (lavapipe for Mesa's CPU "
        "device); " +
        device_list(devices);
  if (!d) return no_device(why);
  out.backend = Backend::Vulkan;
  out.device = *d;
  return Status::ok();
}

Status resolve_backend(const BackendSettings& settings, BackendChoice& out) {
  std::vector<vk::DeviceInfo> devices;
  if (settings.backend == Backend::Vulkan) GIBAKE_TRY(vk::list_devices(devices));
  // auto: no device is worth listing for an unknown workload, and a broken loader means the CPU.
  if (settings.backend == Backend::Auto && settings.workload.known() && !vk::list_devices(devices)) devices.clear();
  return choose_backend(settings, devices, out);
}

Status write_device_list(bool json, std::ostream& out) {
  std::vector<vk::DeviceInfo> devices;
  GIBAKE_TRY(vk::list_devices(devices));
  const vk::DeviceInfo* pick = find_gpu(devices);  // what auto weighs against the CPU
  if (json) {
    nlohmann::json j;
    j["devices"] = nlohmann::json::array();
    for (const auto& d : devices)
      j["devices"].push_back({{"index", d.index},
                              {"name", d.name},
                              {"type", d.type},
                              {"driver", d.driver},
                              {"api", d.api},
                              {"memory_bytes", d.device_memory},
                              {"compute", d.compute},
                              {"lavapipe", d.is_lavapipe()}});
    j["auto"] = pick ? nlohmann::json(pick->index) : nlohmann::json(nullptr);
    out << j.dump(2) << "\n";
    return Status::ok();
  }
  if (devices.empty()) out << "no Vulkan devices (the loader found none); --backend auto uses the CPU\n";
  for (const auto& d : devices) {
    out << "[" << d.index << "] " << d.name << "\n    type " << d.type << ", driver " << d.driver << ", Vulkan "
        << d.api << ", " << (d.device_memory >> 20) << " MiB" << (d.compute ? "" : ", no compute queue (unusable)")
        << (d.is_lavapipe() ? " (lavapipe: --vulkan-device lavapipe)" : "") << "\n";
  }
  if (!devices.empty())
    out << "--backend auto uses "
        << (pick ? "[" + std::to_string(pick->index) + "] " + pick->name +
                       " for bakes the cost model expects to finish sooner there, else the CPU"
                 : std::string("the CPU"))
        << "\n";
  return Status::ok();
}

namespace {

// What every Vulkan context of a bake opens with but the device, which is chosen apart.
vk::ContextOptions context_options(const BackendSettings& settings) {
  vk::ContextOptions o;
  o.validation = settings.validation;
  o.float64 = settings.float64;
  o.max_group_count = settings.vulkan_max_group_count;
  o.device_memory = settings.vulkan_device_memory;
  return o;
}

}  // namespace

Status open_vulkan(const BackendChoice& choice, const BackendSettings& settings, std::unique_ptr<vk::Context>& out) {
  vk::ContextOptions o = context_options(settings);
  o.device_index = choice.device.index;
  return vk::Context::create(o, out);
}

VulkanWarmup::~VulkanWarmup() {
  if (thread_.joinable()) thread_.join();
  if (closer_.joinable()) closer_.join();
}

Status VulkanWarmup::start(const BackendSettings& settings) {
  backend_ = settings.backend;
  if (backend_ == Backend::Cpu) return Status::ok();
  if (backend_ == Backend::Vulkan) return start_named(settings);
  // auto: listing the devices costs the driver's start-up too, so it runs on the thread as well,
  // and the candidate opens on the instance that listed it (vk::Context::create_chosen).
  thread_ = std::thread([this, settings] {
    const auto choose = [&](const std::vector<vk::DeviceInfo>& devices, uint32_t& index) {
      const vk::DeviceInfo* d = auto_candidate(settings, devices);
      kind_ = gpu_kind(d, settings.auto_cpu_device_as_gpu);
      if (kind_ != GpuKind::Discrete && kind_ != GpuKind::Integrated) d = nullptr;
      if (d) choice_.device = *d;
      mark_listed(Status::ok());
      // After the notification take() may change choice_: read only the local candidate.
      if (!d || cancelled_.load()) return false;
      index = d->index;
      return true;
    };
    status_ = vk::Context::create_chosen(context_options(settings), choose, vk_);  // always calls `choose`
  });
  return Status::ok();
}

void VulkanWarmup::mark_listed(const Status& status) {
  {
    std::lock_guard<std::mutex> lock(listed_mutex_);
    listed_ = true;
    listed_status_ = status;
  }
  listed_cv_.notify_all();
}

// vulkan: the device is listed and opened on one instance (vk::Context::create_chosen) on the
// thread, as for auto (two instances would be two driver start-ups before the import). Nothing
// waits here: the listing takes as long as a light bake, so the import runs beside it (a listing that finds no device stops the import; one still under way is
// waited for by the set-up's choose(): a missing device still fails with exit 4).
Status VulkanWarmup::start_named(const BackendSettings& settings) {
  thread_ = std::thread([this, settings] {
    const auto choose = [&](const std::vector<vk::DeviceInfo>& devices, uint32_t& index) {
      const Status chosen = choose_backend(settings, devices, choice_);
      mark_listed(chosen);
      if (!chosen) return false;
      index = choice_.device.index;
      return true;
    };
    status_ = vk::Context::create_chosen(context_options(settings), choose, vk_);  // always calls `choose`
  });
  return Status::ok();
}

Status VulkanWarmup::listed() {
  if (backend_ != Backend::Vulkan) return Status::ok();
  std::unique_lock<std::mutex> lock(listed_mutex_);
  listed_cv_.wait(lock, [this] { return listed_; });
  return listed_status_;
}

bool VulkanWarmup::listing_failed() {
  if (backend_ != Backend::Vulkan) return false;
  std::lock_guard<std::mutex> lock(listed_mutex_);
  return listed_ && !listed_status_;
}

Status VulkanWarmup::take(const WorkloadEstimate& workload, BackendChoice& choice, std::unique_ptr<vk::Context>& out) {
  GIBAKE_TRY(choose(workload, choice));
  return take_device(choice, out);
}

Status VulkanWarmup::take_device(BackendChoice& choice, std::unique_ptr<vk::Context>& out) {
  out.reset();
  if (choice.backend != Backend::Vulkan) return Status::ok();
  if (thread_.joinable()) thread_.join();
  if (backend_ != Backend::Auto) {
    out = std::move(vk_);
    return status_;
  }
  if (!status_) {
    BackendChoice cpu;
    cpu.automatic = true;
    cpu.decision = choice.decision;
    cpu.decision.vulkan = false;
    cpu.decision.reason += "; the GPU did not open (" + status_.message() + ")";
    choice = cpu;
    return Status::ok();
  }
  out = std::move(vk_);
  return Status::ok();
}

Status VulkanWarmup::choose(const WorkloadEstimate& workload, BackendChoice& choice) {
  if (backend_ != Backend::Auto) {
    GIBAKE_TRY(listed());
    choice = choice_;
    return Status::ok();
  }
  // A bake the CPU wins even against the fastest kind of GPU is decided at once, without waiting for
  // the driver to list the devices (as long as a light bake);
  // otherwise as soon as they are listed.
  AutoDecision d = decide_auto(workload, GpuKind::Discrete);
  if (!d.vulkan && workload.known()) {
    d.reason = "a light bake: the CPU is estimated faster than any GPU would be";
  } else {
    if (thread_.joinable()) {
      std::unique_lock<std::mutex> lock(listed_mutex_);
      listed_cv_.wait(lock, [this] { return listed_; });
    }
    d = decide_auto(workload, kind_);  // kind_ is not written after the listing
  }
  BackendChoice chosen = d.vulkan ? choice_ : BackendChoice{};
  chosen.automatic = true;
  chosen.decision = d;
  chosen.backend = d.vulkan ? Backend::Vulkan : Backend::Cpu;
  choice = chosen;
  if (d.vulkan) return Status::ok();  // take_device() waits for it
  // A device not yet opening is never opened (a light bake would otherwise wait for it at exit); one
  // already opening finishes, and closes, beside the bake (the driver's teardown takes tens of ms
  // too). Until the closer joins the opening thread, status_, vk_ and choice_ are that thread's.
  cancelled_.store(true);
  closer_ = std::thread([this, opening = std::move(thread_)]() mutable {
    if (opening.joinable()) opening.join();
    vk_.reset();
  });
  return Status::ok();
}

}  // namespace gibake
