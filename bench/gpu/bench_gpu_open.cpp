// The driver's floor under every Vulkan bake: one process that opens the device as a bake does (one
// instance lists the devices and opens the chosen one, vk::Context::create_chosen), writes 64 MiB to
// it, and closes it. Prints "step seconds" lines (opened, written or uploaded, freed, closed), the
// seconds since the program started, then "device NAME". Run it a few times, as a fresh process each
// (bench/gpu/open_floor.sh): the driver's first open after boot is slower.
// Usage: bench_gpu_open [device index|name|lavapipe]
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/gpu/pick_device.h"

using namespace gibake;

namespace {

using Clock = std::chrono::steady_clock;
const Clock::time_point kStart = Clock::now();

// One line a step: its name and the seconds since the program started.
void mark(const char* step) {
  std::printf("%s %.4f\n", step, std::chrono::duration<double>(Clock::now() - kStart).count());
}

}  // namespace

int main(int argc, char** argv) {
  const std::string want = argc > 1 ? argv[1] : "";
  std::unique_ptr<vk::Context> vk;
  vk::ContextOptions o;
  const auto choose = [&](const std::vector<vk::DeviceInfo>& devices, uint32_t& index) {
    const int i = bench::pick_device(devices, want);
    index = i < 0 ? 0 : uint32_t(i);
    return i >= 0;
  };
  if (Status st = vk::Context::create_chosen(o, choose, vk); !st || !vk)
    return std::fprintf(stderr, "no Vulkan device matching '%s'\n", want.c_str()), 4;
  mark("opened");
  {
    std::vector<uint8_t> bytes(size_t(64) << 20, 0x5a);
    vk::Buffer buffer;
    if (Status st = vk->create_filled_buffer(bytes.data(), bytes.size(), buffer, "bench"); !st)
      return std::fprintf(stderr, "%s\n", st.message().c_str()), 5;
    mark(vk->direct_uploads() ? "written_64MiB_straight" : "uploaded_64MiB_staged");
  }
  mark("freed");
  const std::string name = vk->device().name;
  vk.reset();
  mark("closed");
  std::printf("device %s\n", name.c_str());
  return 0;
}
