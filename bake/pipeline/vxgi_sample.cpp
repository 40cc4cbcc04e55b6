#include "bake/pipeline/vxgi_sample.h"

#include "bake/vulkan/vxgi.h"
#include "io/timer.h"

namespace gibake {

Status sample_vxgi_vulkan(const BackendSettings& settings, const loader::BakeFile& file,
                          std::vector<SamplePoint>& points, DeviceSampleReport& report) {
  report = DeviceSampleReport{};
  BackendSettings vulkan = settings;
  vulkan.backend = Backend::Vulkan;
  BackendChoice choice;
  GIBAKE_TRY(resolve_backend(vulkan, choice));
  std::unique_ptr<vk::Context> vk;
  GIBAKE_TRY(open_vulkan(choice, vulkan, vk));
  std::vector<loader::Vec3> p, n;
  std::vector<size_t> which;
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].rgb.reset();
    for (const loader::VxgiVolume& v : file.vxgi_volumes())
      if (v.contains(points[i].p)) {
        p.push_back(points[i].p);
        n.push_back(points[i].n);
        which.push_back(i);
        break;
      }
  }
  if (p.empty()) return Status::ok();
  std::vector<loader::Rgb> e;
  const auto t0 = Clock::now();
  GIBAKE_TRY(vxgi_diffuse_gpu(*vk, file.vxgi_volumes(), p, n, e));
  report.seconds = seconds_since(t0);
  report.queries = p.size();
  report.device = vk->device().name;
  for (size_t k = 0; k < which.size(); ++k) points[which[k]].rgb = e[k];
  return Status::ok();
}

}  // namespace gibake
