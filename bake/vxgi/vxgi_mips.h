// The anisotropic mip rule (each parent face sees its children through the nearer one's opacity),
// on the layout of io/results/vxgi_result.h.
//
// Face naming: face f = 2*axis + side (+X, -X, +Y, -Y, +Z, -Z) holds the light leaving a voxel
// through its side facing +axis (side 0) or -axis (side 1): what a viewer on that side sees. For a
// parent voxel and face f, the two children of each of the 4 pairs along f's axis are composited
// with the child nearer that viewer in front (the larger coordinate for +axis faces, the smaller
// for -axis faces): pair = front + (1 - front.a) * back on premultiplied RGBA; the parent's face
// is the mean of the 4 pairs. Children beyond an odd-sized grid are empty (0, 0, 0, 0).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

namespace gibake {

// `child`: 6 x child-dims voxels x 4 floats; returns the next level (6 x ceil(dims/2) x 4).
std::vector<float> vxgi_downsample(const std::vector<float>& child, const std::array<int32_t, 3>& child_dims);

}  // namespace gibake
