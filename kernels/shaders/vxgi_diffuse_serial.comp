// vxgi_diffuse.comp with one invocation a group, for Mesa's lavapipe (llvmpipe): llvmpipe leaves
// every loop early once a shader has run 65535 loop iterations, a limit a 64-wide group of cone
// traces can reach. One invocation a group keeps the most headroom (both kernels match the CPU,
// tests/vulkan/gpu_vxgi_test.cpp).
#version 450
#extension GL_GOOGLE_include_directive : require
#define GIBAKE_VXGI_GROUP 1
#include "vxgi_diffuse_main.glsl"
