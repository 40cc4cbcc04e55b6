// Which probes of a volume lie near surfaces (DdgiSettings::near_surface_reach). A sampler reads a
// surface point from the corners of the probe cell it lies in, so a fine volume over a region only
// needs the probes within a couple of spacings of some surface; the rest of its probes sit in open
// space that a coarser volume serves as well, and tracing them costs most of such a volume's time.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <vector>

#include "io/results/ddgi_result.h"

namespace gibake {

class PreparedScene;

// For each probe of `probes` (indices into `desc`'s grid): 1 in the returned mask (probe_count long)
// when no triangle comes within `reach` metres of its rest position (PreparedScene::surface_within:
// either face, a masked triangle whole); 0 for the others and for probes not listed. The same for
// any thread count: each probe's answer is its own.
std::vector<uint8_t> probes_far_from_surfaces(const PreparedScene& scene, const DdgiVolumeDesc& desc,
                                              const std::vector<int32_t>& probes, float reach, tbb::task_arena& arena);

}  // namespace gibake
