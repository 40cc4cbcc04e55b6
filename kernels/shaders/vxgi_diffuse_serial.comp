// vxgi_diffuse.comp with one invocation a group, for Mesa's lavapipe (llvmpipe, LLVM 15): there the
// 64-wide kernel with SDF steps disagrees with the CPU tracer on 18% of test values (up to 58%),
// while this one matches it to 1e-6 (tests/vulkan/gpu_vxgi_test.cpp). The shader uses no subgroup
// or shared-memory operation, so its result must not depend on the group size: the 64-wide
// disagreement is llvmpipe's (its vectorised loop with the SDF read), not the shader's.
#version 450
#extension GL_GOOGLE_include_directive : require
#define GIBAKE_VXGI_GROUP 1
#include "vxgi_diffuse_main.glsl"
