// vxgi_diffuse.comp with one invocation a group, for Mesa's lavapipe (llvmpipe): llvmpipe leaves
// every loop early once a shader has run 65535 loop iterations, and the 64-wide kernel once hit
// that on 18% of test values (vxgi_cone.glsl's level-size loops, since removed: both kernels now
// match the CPU, tests/vulkan/gpu_vxgi_test.cpp). One invocation a group keeps the most headroom.
#version 450
#extension GL_GOOGLE_include_directive : require
#define GIBAKE_VXGI_GROUP 1
#include "vxgi_diffuse_main.glsl"
