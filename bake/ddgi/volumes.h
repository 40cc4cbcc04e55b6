// Several DDGI volumes in one bake: the default grid, the automatic detail volume
// (bake/ddgi/detail_volume.h) and the volumes the user gives (`--probe-volume`), each baked by
// bake_ddgi with the same prepared scene, texture mips, enclosure voxels and device session,
// one after the other, and written as one `ddgi_volume` section group each (docs/FORMAT.md).
//
// The probe budget (--probe-budget) is split: the volumes whose spacing comes from the rule (the
// detail volume, --probe-volume without a spacing) share half of it equally, and the default grid
// keeps the budget less the probes they placed. A --probe-volume with a spacing is outside the
// budget (like --probe-spacing), within --max-probes. Without the default grid the rule-spaced
// volumes share the whole budget. A bake of one volume (no detail volume, no --probe-volume)
// is exactly the bake of one grid, byte for byte. View volumes
// (--near-camera, view_volume.h) have a spacing of their own and are outside the budget too.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/detail_volume.h"
#include "bake/ddgi/refine.h"
#include "bake/ddgi/view_volume.h"

namespace gibake {

struct GivenVolume {  // --probe-volume MIN:MAX[:SPACING][:near]
  std::array<float, 3> lo{}, hi{};
  float spacing = 0.f;  // 0: the default spacing rule on the box, within its budget share
  // Only the probes near surfaces (DdgiSettings::near_surface_reach, kNearSurfaceSpacings of the
  // volume's spacing): a fine volume over a region whose open space the coarser volumes serve.
  bool near_surfaces = false;
};

struct VolumeSettings {
  bool default_volume = true;   // --default-volume on|off: the default grid (probe_grid.h)
  bool detail_volumes = true;   // --detail-volumes auto|off: the automatic rule (detail_volume.h)
  std::vector<GivenVolume> given;
  std::vector<ViewCamera> views;  // --near-camera: a view volume each (view_volume.h), after the given ones
  float view_spacing = 0.f;       // --near-spacing: their spacing; 0: the rule's (view_volume.h)
  DetailRule rule;
  RefineSettings refine;        // --refine-budget: finer volumes where the direct light changes (refine.h)
  uint64_t check_budget = 0;    // --refine-by-check: probes for finer volumes where the bake's check misses
  // Anything but the defaults (a given volume, a rule or the default grid turned off, another
  // refinement budget). Refinement turned off is not: a bake of one grid is the same bytes either way.
  bool customised() const {
    return !default_volume || !detail_volumes || !given.empty() || !views.empty() || refined_otherwise() ||
           check_budget != 0;
  }
  bool refined_otherwise() const {
    return refine.budget != 0 && (refine.budget != RefineSettings{}.budget || refine.any_grid);
  }
};

// BadArguments for an empty request (no default grid, no given volume) or a bad box or spacing.
Status validate_volume_settings(const VolumeSettings& settings);
// The request as a JSON value for the bake's settings (only written when customised()).
std::string volume_settings_json(const VolumeSettings& settings);

enum class VolumeKind { Default, Detail, Given, Refined, View };
const char* volume_kind_name(VolumeKind kind);

struct BakedVolume {
  VolumeKind kind = VolumeKind::Default;
  int given_index = -1;  // Given: which --probe-volume (0-based)
  std::string why;       // one line: why the volume exists
  DdgiResult result;
  DdgiReport report;
};

// Bakes every volume (the default first, then the detail volume, the given ones and the refined
// ones, the file's order). `rule_text` (optional): what the automatic rule found (empty when it did not run);
// `refine_text` (optional): what refinement placed (empty when not asked for).
// With run.shard: the shard's probes of every volume in run.shard->volumes_out, one per volume
// (shard_bake.h; blocks numbered across the volumes, io/results/ddgi_shard.h).
Status bake_ddgi_volumes(const Scene& scene, const DdgiSettings& settings, const VolumeSettings& volumes,
                         const RunContext& run, const Context& ctx, std::vector<BakedVolume>& out,
                         std::string* rule_text = nullptr, std::string* refine_text = nullptr);

// Every volume as a JSON array: index, kind, why, counts, spacing, grid_min, grid_max, probes, active,
// and the rays and ray budget its probes were traced with (from its settings JSON).
std::string volumes_json(const std::vector<BakedVolume>& volumes);

// One line per volume ("volume 1 (detail): 17x7x13 = 1547 probes, 0.52 m, 1210 active; why").
std::string volume_line(size_t index, const BakedVolume& volume);

}  // namespace gibake
