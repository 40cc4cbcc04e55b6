#include "bake/run/backend_cost.h"

#include <algorithm>
#include <cstdio>

namespace gibake {

double WorkloadEstimate::segments() const {
  return double(probes) * (rays * double(1 + std::max(bounces, 0)) + double(relocation_rays));
}

AutoDecision decide_auto(const WorkloadEstimate& w, GpuKind gpu) {
  AutoDecision d;
  if (!w.known()) {
    d.reason = "no workload estimate for this bake (only probe bakes weigh the GPU)";
    return d;
  }
  switch (gpu) {
    case GpuKind::None:
      d.reason = "no Vulkan GPU (discrete or integrated)";
      return d;
    case GpuKind::CpuDevice:
      // lavapipe runs the kernels on these same cores, slower than Embree: never worth it.
      d.reason = "the Vulkan device is a CPU device (lavapipe), never faster than the CPU backend";
      return d;
    case GpuKind::Discrete:
    case GpuKind::Integrated:
      break;
  }
  const double segments = w.segments(), probes = double(w.probes);
  const double threads = double(std::max(w.threads, 1));
  d.cpu_seconds =
      cost::kCpuFixedS + (segments * cost::kCpuSegmentThreadUs + probes * cost::kCpuProbeThreadUs) * 1e-6 / threads;
  const double slow = gpu == GpuKind::Integrated ? cost::kIntegratedSlowdown : 1.0;
  d.vulkan_seconds = cost::kGpuFixedS + double(w.triangles) * cost::kGpuTriangleUs * 1e-6 +
                     slow * (segments * cost::kGpuSegmentUs + probes * cost::kGpuProbeUs) * 1e-6;
  d.vulkan = d.vulkan_seconds < d.cpu_seconds;
  char text[160];
  std::snprintf(text, sizeof text, "%.3g M ray segments over %llu probes, %d CPU threads, %s GPU", segments * 1e-6,
                static_cast<unsigned long long>(w.probes), int(threads),
                gpu == GpuKind::Integrated ? "an integrated" : "a discrete");
  d.reason = text;
  return d;
}

std::string auto_decision_text(const AutoDecision& d) {
  std::string s = std::string("backend auto \xE2\x86\x92 ") + (d.vulkan ? "vulkan" : "cpu");
  if (d.cpu_seconds > 0.0) {
    char est[96];
    std::snprintf(est, sizeof est, " (est. cpu %.2f s, vulkan %.2f s)", d.cpu_seconds, d.vulkan_seconds);
    s += est;
  }
  return s + ": " + d.reason;
}

}  // namespace gibake
