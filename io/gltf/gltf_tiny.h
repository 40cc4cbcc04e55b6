// The one way io/ includes tinygltf: header-only, no stb, no Draco (we decode Draco ourselves).
// The implementation is compiled once, in io/gltf_load.cpp.
#pragma once
#ifndef TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE
#endif
#ifndef TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#endif
#ifdef TINYGLTF_ENABLE_DRACO
#error "gibake decodes Draco itself; TINYGLTF_ENABLE_DRACO must not be defined"
#endif
#include <tiny_gltf.h>
