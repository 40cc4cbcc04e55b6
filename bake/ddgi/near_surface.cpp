#include "bake/ddgi/near_surface.h"

#include <tbb/parallel_for.h>

#include "bake/ddgi/probe_grid.h"
#include "bake/scene/prepare.h"

namespace gibake {

std::vector<uint8_t> probes_far_from_surfaces(const PreparedScene& scene, const DdgiVolumeDesc& desc,
                                              const std::vector<int32_t>& probes, float reach, tbb::task_arena& arena) {
  std::vector<uint8_t> far(size_t(desc.probe_count()), 0);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), probes.size(), [&](size_t i) {
      const int32_t p = probes[i];
      const auto rest = probe_rest_position(desc, p);
      far[size_t(p)] = scene.surface_within(kernels::float3{rest[0], rest[1], rest[2]}, reach) ? 0 : 1;
    });
  });
  return far;
}

}  // namespace gibake
