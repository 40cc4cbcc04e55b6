#include "io/bakefile/bake_match.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "io/bakefile/bake_file.h"

namespace gibake {
namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + items[i];
  return out;
}

// The files whose bytes changed, appeared or went, as one clause (empty when none).
std::string files_clause(const InputChanges& c) {
  std::vector<std::string> parts;
  if (!c.files_changed.empty()) parts.push_back("changed: " + joined(c.files_changed));
  if (!c.files_added.empty()) parts.push_back("now also read: " + joined(c.files_added));
  if (!c.files_removed.empty()) parts.push_back("no longer read: " + joined(c.files_removed));
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? "; " : "") + parts[i];
  return out;
}

}  // namespace

std::string BakeSceneMatch::what() const {
  const std::string files = files_clause(changes);
  if (matches)
    return files.empty() ? std::string()
                         : "files re-saved since the bake with the same content for the bake (" + files + ")";
  if (!by_content)
    return "the scene's files or the bake's settings changed since the bake (a bake from before content hashing "
           "records one hash of the files' bytes, so which file and what changed cannot be told, and a file "
           "re-saved with the same content reads as changed; rebake to record them)";
  if (!changes.parts.empty())
    return "the scene's " + joined(changes.parts) + " changed since the bake" +
           (files.empty() ? std::string() : " (files " + files + ")");
  if (baked_version != version)
    return "baked with gibake " + (baked_version.empty() ? std::string("(unknown)") : baked_version) +
           ", this is gibake " + version;
  return "the settings recorded in the bake file do not give its input hash (the file's metadata was edited "
         "after the bake)";
}

Status match_bake_to_scene(const loader::BakeFile& file, const Scene& scene, BakeSceneMatch& out) {
  out = BakeSceneMatch{};
  out.bake_hash = file.header().input_hash;
  out.version = gibake_version_string();
  const nlohmann::json meta = nlohmann::json::parse(file.metadata_json(), nullptr, false);
  const bool object = !meta.is_discarded() && meta.is_object();
  const std::string settings = object && meta.contains("settings") ? meta["settings"].dump() : std::string();
  if (object && meta.contains("version") && meta["version"].is_string()) out.baked_version = meta["version"].get<std::string>();
  InputDigest baked;
  if (object && meta.contains("inputs") && input_digest_from_json(meta["inputs"], baked)) {
    out.by_content = true;
    InputDigest now = digest_scene(scene);
    GIBAKE_TRY(digest_files(scene.input_files, now));
    out.scene_hash = content_input_hash(now, settings, out.version);
    out.changes = compare_digests(baked, now);
  } else {
    GIBAKE_TRY(hash_inputs(scene.input_files, settings, out.scene_hash));
  }
  out.matches = out.scene_hash == out.bake_hash;
  return Status::ok();
}

}  // namespace gibake
