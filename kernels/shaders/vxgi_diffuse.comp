// Diffuse cone-traced irradiance at query points (vxgi_diffuse_main.glsl): the Vulkan kernel CI
// checks against the loader's CPU tracer, 64 invocations a group.
#version 450
#extension GL_GOOGLE_include_directive : require
#define GIBAKE_VXGI_GROUP 64
#include "vxgi_diffuse_main.glsl"
