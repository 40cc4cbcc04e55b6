#include "bake/ddgi/near_surface.h"

#include <tbb/parallel_for.h>

#include "bake/ddgi/ddgi.h"
#include "bake/scene/prepare.h"
#include "kernels/ray_gen.h"

namespace gibake {

std::vector<uint8_t> probes_far_from_surfaces(const PreparedScene& scene, const DdgiVolumeDesc& desc,
                                              const std::vector<int32_t>& probes, float reach, tbb::task_arena& arena) {
  std::vector<uint8_t> far(size_t(desc.probe_count()), 0);
  std::vector<float> dirs(size_t(kNearSurfaceDirections) * 3);
  kernels::spherical_fibonacci_set(kNearSurfaceDirections, dirs.data());
  arena.execute([&] {
    tbb::parallel_for(size_t(0), probes.size(), [&](size_t i) {
      const int32_t p = probes[i];
      const auto rest = probe_rest_position(desc, p);
      const kernels::float3 at{rest[0], rest[1], rest[2]};
      bool near = false;
      for (uint32_t k = 0; k < kNearSurfaceDirections && !near; ++k) {
        const kernels::float3 d{dirs[k * 3], dirs[k * 3 + 1], dirs[k * 3 + 2]};
        near = scene.occluded(at, d, 0.f, reach);
      }
      far[size_t(p)] = near ? 0 : 1;
    });
  });
  return far;
}

}  // namespace gibake
