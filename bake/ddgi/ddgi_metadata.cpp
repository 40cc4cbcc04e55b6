#include "bake/ddgi/ddgi_metadata.h"

namespace gibake {

void add_ddgi_report_metadata(const DdgiReport& r, nlohmann::json& meta) {
  meta["probes"] = {{"total", r.probes},      {"active", r.active},     {"inactive", r.inactive},
                    {"enclosed", r.enclosed}, {"sky_only", r.sky_only}, {"relocated", r.relocated}};
  if (r.left_out > 0) meta["probes"]["left_out"] = r.left_out;  // only then: other files keep their bytes
  meta["closed_mesh_check"] = {{"checked", r.cgal_checked},
                               {"inside", r.cgal_inside},
                               {"inside_but_active", r.cgal_disagreements},
                               {"inactive_outside_closed", r.cgal_inactive_outside}};
  meta["rays"] = {{"primary", r.primary_rays},
                  {"bounce", r.bounce_rays},
                  {"shadow", r.shadow_rays},
                  {"relocation", r.relocation_rays}};
}

}  // namespace gibake
