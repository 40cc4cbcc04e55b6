// Every glTF/GLB in the validator test corpus and the malformed set imports or fails cleanly.
#include <map>

#include "tests/io/import_testutil.h"

namespace gibake::test {
namespace {

std::vector<std::string> scene_files(const std::string& root) {
  std::vector<std::string> out;
  if (!fs::exists(root)) return out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb")) out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// numErrors from the validator report beside `file`, or -1 without one.
int report_errors(const std::string& file) {
  std::string report = file.substr(0, file.rfind('.')) + ".report.json";
  if (!fs::exists(report)) report = file + ".report.json";
  if (!fs::exists(report)) return -1;
  json j = json::parse(read_file(report), nullptr, false);
  if (j.is_discarded() || !j.contains("issues")) return -1;
  return j["issues"].value("numErrors", -1);
}

// Whether a document places any triangle primitive (a node with a mesh, a primitive of mode
// TRIANGLES/STRIP/FAN): valid files without one may be refused as "scene has no triangles".
bool places_triangles(const std::string& file) {
  std::string text = read_file(file);
  if (file.size() > 4 && file.substr(file.size() - 4) == ".glb") {
    if (text.size() < 20) return false;
    uint32_t n;
    std::memcpy(&n, text.data() + 12, 4);
    text = text.substr(20, n);
  }
  json d = json::parse(text, nullptr, false);
  if (d.is_discarded() || !d.contains("nodes") || !d.contains("meshes")) return false;
  bool node_mesh = false, tri = false;
  for (const auto& n : d["nodes"]) node_mesh = node_mesh || (n.is_object() && n.contains("mesh"));
  for (const auto& m : d["meshes"])
    if (m.is_object() && m.contains("primitives"))
      for (const auto& p : m["primitives"]) {
        int mode = p.is_object() ? p.value("mode", 4) : 0;
        tri = tri || mode == 4 || mode == 5 || mode == 6;
      }
  return node_mesh && tri;
}

// Refusals that are policy, not bugs: URIs that leave the folder or use a scheme.
bool policy_refusal(const Status& s) {
  const std::string& w = s.where();
  return w.size() > 4 && w.substr(w.size() - 4) == ".uri";
}

bool clean_failure(const Status& s) {
  return (s.code() == ExitCode::InvalidInput || s.code() == ExitCode::IoFailure) && !s.what().empty();
}

TEST(BadInputCorpus, ValidatorFilesImportOrFailCleanly) {
  auto files = scene_files(asset("gltf-validator-tests"));
  ASSERT_GT(files.size(), 300u);
  std::map<std::string, int> tally;
  std::vector<std::string> valid_refused;
  for (const auto& f : files) {
    ImportOptions opt;
    auto r = import_file(f, opt);
    int errors = report_errors(f);
    if (r.status.is_ok()) {
      tally[errors == 0 ? "valid, imported" : "invalid, imported anyway"]++;
      if (errors != 0) std::printf("  invalid, imported anyway: %s\n", f.c_str());
      EXPECT_GT(r.scene.triangle_count(), 0u) << f;
      continue;
    }
    EXPECT_TRUE(clean_failure(r.status)) << f << ": " << r.status.message();
    EXPECT_TRUE(r.scene.positions.empty()) << f;
    if (errors != 0) {
      tally["invalid, refused"]++;
    } else if (r.status.what() == "scene has no triangles") {
      tally["valid, no triangles"]++;
    } else if (!places_triangles(f)) {
      tally["valid, no triangles, refused"]++;
    } else if (r.status.what().find("data is not available") != std::string::npos) {
      tally["valid, buffer data absent"]++;
    } else if (policy_refusal(r.status)) {
      tally["valid, refused by URI policy"]++;
      std::printf("  URI policy: %s\n", r.status.message().c_str());
    } else {
      tally["valid, refused"]++;
      valid_refused.push_back(f + ": " + r.status.message());
    }
  }
  std::printf("validator corpus: %zu files\n", files.size());
  for (const auto& [k, v] : tally) std::printf("  %-26s %d\n", k.c_str(), v);
  for (const auto& v : valid_refused) std::printf("  valid but refused: %s\n", v.c_str());
  EXPECT_TRUE(valid_refused.empty());
}

TEST(BadInputCorpus, MalformedFilesFailCleanly) {
  auto files = scene_files(asset("malformed"));
  ASSERT_GT(files.size(), 5u);
  int ok = 0, refused = 0;
  for (const auto& f : files) {
    auto r = import_file(f);
    if (r.status.is_ok()) {
      ++ok;
      EXPECT_GT(r.scene.triangle_count(), 0u) << f;
      std::printf("  imported: %s (%zu triangles)\n", f.c_str(), r.scene.triangle_count());
    } else {
      ++refused;
      EXPECT_TRUE(clean_failure(r.status)) << f << ": " << r.status.message();
      std::printf("  refused:  %s\n", r.status.message().c_str());
    }
  }
  std::printf("malformed: %zu files, %d imported, %d refused\n", files.size(), ok, refused);
}

}  // namespace
}  // namespace gibake::test
