#include "bake/voxel/leak_warnings.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

namespace gibake {

float coarsest_spacing(const std::array<float, 3>& spacing) {
  float coarsest = 0.f;
  for (float sp : spacing) coarsest = std::max(coarsest, sp);
  return coarsest;
}

Status audit_and_warn(const VoxelGrid& voxels, const PreparedScene& prepared,
                      const std::vector<kernels::ShadeLight>& lights, float probe_spacing, const Context& ctx,
                      LeakAudit& out, bool& ran) {
  ran = false;
  if (!(probe_spacing > 0.f)) return Status::ok();
  LeakAuditSettings ls;
  ls.probe_spacing = probe_spacing;
  ls.max_regions = SIZE_MAX;  // all of them for --format json; the largest are warned about
  GIBAKE_TRY(audit_leaks(voxels, prepared, lights, ls, ctx, out));
  constexpr size_t kMaxWarned = 8;
  for (size_t i = 0; i < out.regions.size() && i < kMaxWarned; ++i)
    ctx.warning(describe_leak(out.regions[i], ls.probe_spacing));
  if (out.regions.size() > kMaxWarned)
    ctx.warning("leak risk: " + std::to_string(out.regions.size() - kMaxWarned) +
                " more thin-wall regions between lit and unlit space (smaller than those above)");
  ran = true;
  return Status::ok();
}

namespace {
constexpr size_t kMaxLeakWarnings = 3;  // the most light; the rest as a count (the report lists all)

std::string exposure_text(const LeakExposure& e) {
  char text[160];
  std::snprintf(text, sizeof text, "%d active probe%s across it, up to %.3g cd/m^2 of difference", e.probes_across,
                e.probes_across == 1 ? "" : "s", double(e.radiance_across));
  return text;
}
}  // namespace

Status audit_bake_leaks(const VoxelGrid& voxels, const PreparedScene& prepared,
                        const std::vector<kernels::ShadeLight>& lights, const DdgiResult& probes, const Context& ctx,
                        LeakAudit& out, std::vector<LeakExposure>& exposure, bool& ran) {
  ran = false;
  LeakAuditSettings ls;
  ls.probe_spacing = coarsest_spacing(probes.desc.spacing);
  if (!(ls.probe_spacing > 0.f)) return Status::ok();  // a single probe: nothing to blend across
  ls.max_regions = SIZE_MAX;                            // the report and JSON list them all
  GIBAKE_TRY(audit_leaks(voxels, prepared, lights, ls, ctx, out));
  exposure = leak_exposure(out, probes, prepared);
  const std::vector<LeakExposure> ranked = ranked_exposed(exposure);
  for (size_t i = 0; i < ranked.size() && i < kMaxLeakWarnings; ++i)
    ctx.warning(describe_leak(out.regions[ranked[i].region], ls.probe_spacing) + " [" + exposure_text(ranked[i]) + "]");
  if (ranked.size() > kMaxLeakWarnings)
    ctx.warning("leak risk: " + std::to_string(ranked.size() - kMaxLeakWarnings) +
                " more thin walls that active probes blend across (less light than those above; the report lists them)");
  ran = true;
  return Status::ok();
}

std::vector<std::string> leak_region_lines(const LeakAudit& audit, const std::vector<LeakExposure>& exposure) {
  std::vector<std::string> lines;
  for (size_t i = 0; i < audit.regions.size(); ++i) {
    const bool exposed = i < exposure.size() && exposure[i].probes_across > 0;
    lines.push_back(describe_leak(audit.regions[i], audit.probe_spacing) + " [" +
                    (exposed ? exposure_text(exposure[i]) + "; warned"
                             : std::string("no active probes blend across it; not warned")) +
                    "]");
  }
  return lines;
}

// Every region (not only the warned ones), with the probes across it.
nlohmann::json leak_json(const LeakAudit& audit, const std::vector<LeakExposure>* exposure) {
  nlohmann::json list = nlohmann::json::array();
  size_t warned = 0;
  for (size_t i = 0; i < audit.regions.size(); ++i) {
    const LeakRegion& r = audit.regions[i];
    const int across = exposure && i < exposure->size() ? (*exposure)[i].probes_across : 0;
    warned += across > 0;
    list.push_back({{"min", r.min}, {"max", r.max}, {"axis", std::string(1, "xyz"[r.axis])}, {"thickness", r.thickness},
                    {"voxels", r.voxels}, {"lit_point", r.lit_point}, {"dark_point", r.dark_point},
                    {"dark_enclosed", r.dark_enclosed}, {"active_probes_across", across},
                    {"radiance_across", across ? (*exposure)[i].radiance_across : 0.f}, {"warned", across > 0}});
  }
  return {{"probe_spacing", audit.probe_spacing}, {"thin_wall_crossings", audit.thin_wall_crossings},
          {"leak_voxels", audit.leak_voxels}, {"regions", audit.regions_total}, {"warned", warned},
          {"region_list", list}};
}

}  // namespace gibake
