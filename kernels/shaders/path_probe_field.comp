// The path kernel (path_kernel.glsl) whose mode 2 also records where each path would end at its
// first hit in a bake's probes: the surface fit's paths, both estimates from one path
// (probe_field_ended.comp lights the first hits from the probes).
#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#define PATH_PROBE_FIELD
#include "gpu_types.h"
#include "path_kernel.glsl"
