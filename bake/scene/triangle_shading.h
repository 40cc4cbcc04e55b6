// A triangle's shading attributes packed into one record (material, corner indices, uvs and
// normals), kept in the order the trace finds triangles in: a hit then reads one place in memory
// instead of the scene's separate index, uv, normal and material arrays, which random hits over a
// large scene find in as many cache lines. The values are the scene's own; a lookup by triangle
// index builds the record and reads it the same way (bake/scene/material.h).
#pragma once
#include <cstdint>

namespace gibake {

struct TriangleShading {
  uint32_t triangle = 0;    // index into Scene triangles
  int32_t material = -1;    // index into Scene::materials, or -1 (the default material)
  uint32_t vertex[3] = {};  // the triangle's vertex indices
  float uv[6] = {};         // corner uvs (TEXCOORD_0), zeros when the scene has none
  float normal[9] = {};     // corner normals, zeros when the scene has none
};
static_assert(sizeof(TriangleShading) == 80, "one record: 80 bytes");

}  // namespace gibake
