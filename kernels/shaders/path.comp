// The path kernel (path_kernel.glsl): the probe gathers and the reconstruction check's reference paths.
#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "gpu_types.h"
#include "path_kernel.glsl"
