// The probe and ray counts of a DDGI bake in the bake file's metadata: written by `gibake bake` and,
// from the assembled shards, by `gibake merge`, which must give the same bytes.
#pragma once
#include <nlohmann/json.hpp>

#include "bake/ddgi/ddgi.h"

namespace gibake {

// Adds "probes", "closed_mesh_check" and "rays" to `meta`.
void add_ddgi_report_metadata(const DdgiReport& r, nlohmann::json& meta);

}  // namespace gibake
