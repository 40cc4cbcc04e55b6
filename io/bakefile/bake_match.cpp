#include "io/bakefile/bake_match.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "io/bakefile/bake_file.h"

namespace gibake {

std::string hash_text(uint64_t hash) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(hash));
  return text;
}

Status match_bake_to_scene(const loader::BakeFile& file, const std::vector<std::string>& scene_files,
                           BakeSceneMatch& out) {
  out = BakeSceneMatch{};
  out.bake_hash = file.header().input_hash;
  const nlohmann::json meta = nlohmann::json::parse(file.metadata_json(), nullptr, false);
  const bool has_settings = !meta.is_discarded() && meta.is_object() && meta.contains("settings");
  GIBAKE_TRY(hash_inputs(scene_files, has_settings ? meta["settings"].dump() : std::string(), out.scene_hash));
  out.matches = out.scene_hash == out.bake_hash;
  return Status::ok();
}

}  // namespace gibake
