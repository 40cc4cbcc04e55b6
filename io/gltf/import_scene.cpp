// gibake::import_scene: glTF/GLB -> Scene. Every exception stops at this boundary.
#include <cmath>
#include <exception>
#include <map>
#include <new>
#include <utility>

#include "io/gltf/gltf_deform.h"
#include "io/gltf/gltf_emit.h"
#include "io/gltf/gltf_lights.h"
#include "io/gltf/gltf_load.h"
#include "io/gltf/gltf_materials.h"
#include "io/gltf/gltf_mesh.h"
#include "io/gltf/gltf_nodes.h"
#include "io/gltf/import.h"

namespace gibake {
namespace gltf {
namespace {

void count_stats(const tinygltf::Model& m, ImportStats& s) {
  s.meshes = m.meshes.size();
  s.nodes = m.nodes.size();
  s.cameras = m.cameras.size();
  for (const auto& mesh : m.meshes)
    for (const auto& p : mesh.primitives) {
      ++s.primitives;
      if (p.extensions.count("KHR_draco_mesh_compression")) ++s.draco_primitives;
      if (p.mode >= 0 && p.mode <= 3) ++s.skipped_primitives;
    }
}

// Perspective cameras of the placed nodes: position, -Z forward and +Y up through the world matrix.
void import_cameras(const ImportEnv& env, const std::vector<NodeInstance>& nodes, Scene& scene) {
  const auto& cams = env.model->cameras;
  for (const NodeInstance& ni : nodes) {
    const int c = env.model->nodes[size_t(ni.node)].camera;
    if (c < 0 || size_t(c) >= cams.size() || cams[size_t(c)].type != "perspective") continue;
    const auto& w = ni.world;  // column-major
    auto dir = [&w](double x, double y, double z) {
      const double d[3] = {w[0] * x + w[4] * y + w[8] * z, w[1] * x + w[5] * y + w[9] * z,
                           w[2] * x + w[6] * y + w[10] * z};
      const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      return l > 0 ? Vec3f{float(d[0] / l), float(d[1] / l), float(d[2] / l)} : Vec3f{0.f, 0.f, 0.f};
    };
    Camera cam;
    cam.name = cams[size_t(c)].name;
    cam.position = {float(w[12]), float(w[13]), float(w[14])};
    const std::string where = at("nodes", size_t(ni.node));
    // A view is not needed to bake: a camera the tools cannot use is left out, and said so.
    if (Status far = env.check_coordinates(where, "camera position", cam.position.data()); !far) {
      env.ctx->warning(far.message() + "; camera ignored");
      continue;
    }
    cam.forward = dir(0, 0, -1);
    cam.up = dir(0, 1, 0);
    const double yfov = cams[size_t(c)].perspective.yfov, aspect = cams[size_t(c)].perspective.aspectRatio;
    if (std::isfinite(yfov) && yfov > 0 && yfov < 3.1)
      cam.yfov = float(yfov);
    else
      env.ctx->warning(env.file + ": " + at("cameras", size_t(c)) + ".perspective.yfov: " + std::to_string(yfov) +
                       " is not within (0, 3.1) radians; the default field of view used");
    if (std::isfinite(aspect) && aspect > 0) cam.aspect = float(aspect);
    if (cam.forward[0] == 0.f && cam.forward[1] == 0.f && cam.forward[2] == 0.f) continue;  // degenerate matrix
    scene.cameras.push_back(cam);
  }
}

// Decoded primitives of one mesh at one set of morph weights, decoded on first use and shared by
// every node that places it so.
struct MeshCache {
  std::map<std::pair<size_t, std::vector<double>>, std::vector<PrimitiveData>> meshes;
};

Status mesh_data(const ImportEnv& env, MeshCache& cache, size_t mesh, const std::vector<double>& weights,
                 const std::vector<PrimitiveData>*& out) {
  const auto key = std::make_pair(mesh, weights);
  auto it = cache.meshes.find(key);
  if (it == cache.meshes.end()) {
    const auto& prims = env.model->meshes[mesh].primitives;
    std::vector<PrimitiveData> decoded(prims.size());
    for (size_t p = 0; p < prims.size(); ++p) GIBAKE_TRY(decode_primitive(env, mesh, p, weights, decoded[p]));
    it = cache.meshes.emplace(key, std::move(decoded)).first;
  }
  out = &it->second;
  return Status::ok();
}

// A primitive of a skinned node, posed by its joints (gltf_deform.h) and placed in world space as
// it stands; a primitive without joints is placed by the node's transform.
Status emit_skinned(const ImportEnv& env, const NodeInstance& ni, int skin, const std::vector<Mat4>& worlds,
                    size_t mesh, size_t p, const PrimitiveData& d, Scene& scene) {
  const std::string where = at("nodes", size_t(ni.node));
  if (d.influences == 0) {
    env.ctx->warning(env.file + ": " + at("meshes", mesh, "primitives", p) +
                     ": no JOINTS_0/WEIGHTS_0 for the skin of " + where + "; placed by the node's transform");
    return emit_instance(env, ni, mesh, p, d, scene);
  }
  PrimitiveData posed;
  GIBAKE_TRY(skin_primitive(env, where, skin, worlds, d, posed));
  return emit_instance(env, NodeInstance{ni.node, mat_identity()}, mesh, p, posed, scene);
}

// A finite world matrix of determinant 0: glTF allows a scale of 0 (it hides a node), but its
// mesh has no normals. Left out; a matrix that is not finite is refused when its mesh is placed.
bool flattened(const Mat4& world) {
  for (double v : world)
    if (!std::isfinite(v)) return false;
  return mat_det3(world) == 0.0;
}

Status place_meshes(const ImportEnv& env, const std::vector<NodeInstance>& nodes, Scene& scene) {
  const auto& m = *env.model;
  MeshCache cache;
  std::vector<Mat4> worlds;  // every node's, once a skinned node needs its joints'
  size_t flat = 0;  // mesh nodes of scale 0, left out
  int first_flat = -1;
  for (size_t k = 0; k < nodes.size(); ++k) {
    if (env.options->cancelled && env.options->cancelled()) return env.invalid("nodes", "import cancelled");
    env.ctx->report("import", double(k), double(nodes.size()));
    const tinygltf::Node& node = m.nodes[size_t(nodes[k].node)];
    const int mesh = node.mesh;
    if (mesh < 0) continue;
    const std::string where = at("nodes", size_t(nodes[k].node));
    if (size_t(mesh) >= m.meshes.size()) return env.invalid(where, "mesh index out of range");
    const int skin = node.skin;
    if (skin >= 0 && size_t(skin) >= m.skins.size()) return env.invalid(where, "skin index out of range");
    if (skin < 0 && flattened(nodes[k].world)) {
      if (flat++ == 0) first_flat = nodes[k].node;
      continue;
    }
    if (skin >= 0 && worlds.empty()) GIBAKE_TRY(node_world_matrices(env, worlds));
    const std::vector<PrimitiveData>* prims = nullptr;
    GIBAKE_TRY(mesh_data(env, cache, size_t(mesh), morph_weights(node, m.meshes[size_t(mesh)]), prims));
    for (size_t p = 0; p < prims->size(); ++p) {
      const PrimitiveData& d = (*prims)[p];
      if (d.skipped || d.indices.empty()) continue;
      GIBAKE_TRY(skin >= 0 ? emit_skinned(env, nodes[k], skin, worlds, size_t(mesh), p, d, scene)
                           : emit_instance(env, nodes[k], size_t(mesh), p, d, scene));
    }
  }
  env.ctx->report("import", double(nodes.size()), double(nodes.size()));
  // One line for them all: a file may hide many nodes so.
  if (flat > 0)
    env.ctx->warning(env.file + ": " + at("nodes", size_t(first_flat)) +
                     (flat > 1 ? " and " + std::to_string(flat - 1) + " more mesh nodes" : std::string()) +
                     ": a scale of 0 flattens " + (flat > 1 ? "them" : "it") +
                     " (the world matrix is not invertible); left out");
  return Status::ok();
}

bool any_colors(const tinygltf::Model& m, const Scene& s) {
  for (const auto& inst : s.instances) {
    const auto& p = m.meshes[size_t(inst.mesh)].primitives[size_t(inst.primitive)];
    if (p.attributes.count("COLOR_0")) return true;
  }
  return false;
}

Status import_impl(const std::string& path, const ImportOptions& options, const Context& ctx, Scene& out) {
  tinygltf::Model model;
  ImportEnv env;
  env.file = path;
  env.options = &options;
  env.ctx = &ctx;
  env.model = &model;
  out.source_path = path;
  // Nodes and meshes read no pixels: they are converted while the images decode. A material's
  // error still comes first, as when materials were read before the meshes.
  std::vector<NodeInstance> nodes;
  Status meshes = Status::ok();
  GIBAKE_TRY(load_model(path, options, ctx, model, out.input_files, out.missing_inputs, [&] {
    count_stats(model, out.stats);
    meshes = collect_scene_nodes(env, nodes);
    if (meshes.is_ok()) meshes = place_meshes(env, nodes, out);
  }));
  if (options.cancelled && options.cancelled()) return env.invalid("", "import cancelled");
  GIBAKE_TRY(import_materials(env, model.images, out));
  GIBAKE_TRY(meshes);
  GIBAKE_TRY(import_lights(env, nodes, out));
  import_cameras(env, nodes, out);
  if (out.triangle_count() == 0) return env.invalid("scene", "scene has no triangles");
  if (!any_colors(model, out)) out.colors.clear();
  return Status::ok();
}

}  // namespace
}  // namespace gltf

Status import_scene(const std::string& path, const ImportOptions& options, const Context& ctx, Scene& out) {
  out = Scene();
  Status s;
  try {
    s = gltf::import_impl(path, options, ctx, out);
  } catch (const std::bad_alloc&) {
    s = Status::invalid(path, "", "out of memory while importing (file too large or hostile)");
  } catch (const std::exception& e) {
    s = Status::invalid(path, "", std::string("import failed: ") + e.what());
  } catch (...) {
    s = Status::invalid(path, "", "import failed with an unknown error");
  }
  if (!s.is_ok()) out = Scene();
  return s;
}

}  // namespace gibake
