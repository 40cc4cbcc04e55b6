// The relocation stage: `iterations` passes of geometry-only rays from every probe, each pass
// moving probes away from nearby front faces (bake/ddgi/relocate.h). The rays run on the bake's
// device (bake/ddgi/ddgi_device.h), which reduces each probe's pass to RelocationSums, so
// apply_relocation sees the same input on every backend.
#pragma once
#include <cstdint>
#include <vector>

#include "bake/ddgi/ddgi_device.h"
#include "bake/ddgi/relocate.h"
#include "io/context.h"

namespace gibake {

// Relocation batches use pass numbers above any bake batch, so their rays never repeat a bake ray.
constexpr uint32_t kRelocatePassBase = 0x40000000u;

struct RelocationStage {
  RelocationRays rays;  // threshold and passes are filled from params and iterations
  int iterations = 0;
  RelocateParams params;
};

// Runs every pass over `probes`. Per probe: `offsets` (xyz, updated), `moved` (set to 1 when it
// moved) and `rays` (incremented by the rays traced). Deterministic for any thread count.
Status relocate_probes(const RelocationStage& stage, DdgiDevice& device, const std::vector<int32_t>& probes,
                       const Context& ctx, std::vector<float>& offsets, std::vector<uint8_t>& moved,
                       std::vector<uint64_t>& rays);

}  // namespace gibake
