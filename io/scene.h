// The imported scene: world-space triangles, materials, textures and lights.
// Produced by io::import_scene, consumed by the bakers. Plain data, no dependencies.
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace gibake {

using Vec3f = std::array<float, 3>;

// The largest coordinate, in metres either side of the origin, of a place rays start from or aim at
// (vertices, lights, cameras, probe volumes). The ray tracer takes points up to about 1.8e18 from
// the origin; rays also start beyond a scene's bounds (probes in its padding, cameras), so places
// keep well inside that.
constexpr double kMaxSceneCoordinate = 1e16;

struct Bounds {
  Vec3f min{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
            std::numeric_limits<float>::max()};
  Vec3f max{-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
            -std::numeric_limits<float>::max()};
  bool empty() const { return min[0] > max[0]; }
  void extend(const Vec3f& p) {
    for (int i = 0; i < 3; ++i) {
      if (p[i] < min[i]) min[i] = p[i];
      if (p[i] > max[i]) max[i] = p[i];
    }
  }
};

// Decoded image, 8 bits per channel RGBA as stored in the file (not yet sRGB-decoded:
// the material slot that references it decides the colour space).
struct Texture {
  std::string name;
  int width = 0, height = 0;
  std::vector<uint8_t> rgba8;  // width*height*4
  // glTF sampler wrap modes (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT).
  int wrap_s = 10497, wrap_t = 10497;
};

// A material slot's texture, with KHR_texture_transform applied as
// uv' = T * R * S * uv (glTF extension order).
struct TextureRef {
  int texture = -1;  // index into Scene::textures, -1 = none
  int texcoord = 0;  // only TEXCOORD_0 is carried; other sets fall back to uv0 with a warning
  float offset[2] = {0.f, 0.f};
  float scale[2] = {1.f, 1.f};
  float rotation = 0.f;  // radians
  bool has_transform = false;
};

enum class AlphaMode : uint8_t { Opaque = 0, Mask = 1, Blend = 2 };
// Every tracer (bakes, voxels, previews) treats BLEND as MASK with this cutoff unless told
// otherwise (--blend-cutoff); <= 0 traces BLEND as opaque.
constexpr float kDefaultBlendCutoff = 0.5f;

struct Material {
  std::string name;
  float base_color[4] = {1.f, 1.f, 1.f, 1.f};  // linear
  TextureRef base_color_texture;                // sRGB-decoded when sampled
  float emissive[3] = {0.f, 0.f, 0.f};          // emissiveFactor (linear)
  float emissive_strength = 1.f;                // KHR_materials_emissive_strength
  TextureRef emissive_texture;                  // sRGB-decoded when sampled
  float metallic = 1.f, roughness = 1.f;        // carried, bakers treat surfaces as Lambertian
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
  // KHR_materials_transmission: transmissionFactor in [0, 1] times the texture's red channel
  // (linear): traced as a thin surface, a fraction t of the light passes straight through, tinted
  // by the base colour. 0: opaque, whatever the texture.
  float transmission = 0.f;
  TextureRef transmission_texture;

  bool is_emissive() const {
    return emissive_strength > 0.f && (emissive[0] > 0.f || emissive[1] > 0.f || emissive[2] > 0.f);
  }
};

// KHR_lights_punctual, in world space. Photometric units (DESIGN.md):
// directional intensity is lux, point/spot intensity is candela.
struct Light {
  enum class Type : uint8_t { Directional = 0, Point = 1, Spot = 2 };
  std::string name;
  Type type = Type::Point;
  float color[3] = {1.f, 1.f, 1.f};  // linear
  float intensity = 1.f;
  Vec3f position{0.f, 0.f, 0.f};
  Vec3f direction{0.f, 0.f, -1.f};  // unit vector the light travels along (glTF -Z of the node)
  float range = 0.f;                 // 0 = infinite
  float inner_cone_angle = 0.f;      // radians (spot)
  float outer_cone_angle = 0.7853982f;
};

// A glTF perspective camera placed by its node (the node's -Z looks forward, +Y is up).
struct Camera {
  std::string name;
  Vec3f position{0.f, 0.f, 0.f};
  Vec3f forward{0.f, 0.f, -1.f};  // unit
  Vec3f up{0.f, 1.f, 0.f};        // unit, orthogonal to forward
  float yfov = 0.8f;              // vertical field of view, radians
  float aspect = 0.f;             // width / height; 0 = not given
};

// One placed mesh primitive: a contiguous run of triangles.
struct PrimitiveInstance {
  uint32_t first_triangle = 0, triangle_count = 0;
  int mesh = -1, primitive = -1, node = -1;
  bool draco = false;
  bool mirrored = false;  // world matrix had negative determinant (winding was flipped)
};

struct ImportStats {
  size_t meshes = 0, nodes = 0, primitives = 0, draco_primitives = 0;
  size_t skipped_primitives = 0;  // POINTS/LINES
  size_t cameras = 0;
};

struct Scene {
  std::string source_path;
  // Per vertex, world space. normals are unit length; colors may be empty (all white).
  std::vector<float> positions;  // xyz
  std::vector<float> normals;    // xyz
  std::vector<float> uvs;        // uv0
  std::vector<float> colors;     // rgba, linear (COLOR_0), empty when no primitive has it
  // Per triangle: counter-clockwise in world space seen from the front.
  std::vector<uint32_t> indices;       // 3 per triangle
  std::vector<int32_t> tri_material;   // index into materials; -1 = default material
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  std::vector<Camera> cameras;  // perspective cameras in node order (orthographic ones skipped)
  std::vector<PrimitiveInstance> instances;
  Bounds bounds;
  ImportStats stats;
  // Every file the import read (scene, buffers, images): for depfiles and input hashes.
  std::vector<std::string> input_files;
  // Image files the scene names that did not exist (warned, ignored): a depfile lists them too, so
  // that a build bakes again once they appear.
  std::vector<std::string> missing_inputs;

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

// Whether some triangle has an area (its edges' cross product is not 0): triangles of none light nothing and bound no
// volume, so a scene of them alone has nothing to bake.
inline bool any_triangle_has_area(const Scene& s) {
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const float* p[3];
    for (size_t k = 0; k < 3; ++k) p[k] = &s.positions[size_t(s.indices[t * 3 + k]) * 3];
    double e1[3], e2[3];
    for (int a = 0; a < 3; ++a) e1[a] = double(p[1][a]) - p[0][a], e2[a] = double(p[2][a]) - p[0][a];
    if (e1[1] * e2[2] != e1[2] * e2[1] || e1[2] * e2[0] != e1[0] * e2[2] || e1[0] * e2[1] != e1[1] * e2[0]) return true;
  }
  return false;
}

}  // namespace gibake
