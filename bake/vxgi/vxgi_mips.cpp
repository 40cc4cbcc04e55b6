#include "bake/vxgi/vxgi_mips.h"

#include "io/results/vxgi_result.h"

namespace gibake {

std::vector<float> vxgi_downsample(const std::vector<float>& child, const std::array<int32_t, 3>& cd) {
  const std::array<int32_t, 3> pd = vxgi_level_dims(cd, 1);
  const size_t child_cells = size_t(cd[0]) * size_t(cd[1]) * size_t(cd[2]);
  const size_t parent_cells = size_t(pd[0]) * size_t(pd[1]) * size_t(pd[2]);
  std::vector<float> out(size_t(kVxgiFaces) * parent_cells * 4, 0.f);
  static const float kZero[4] = {0.f, 0.f, 0.f, 0.f};
  for (int f = 0; f < kVxgiFaces; ++f) {
    const int axis = f / 2;
    const int front_bit = f % 2 == 0 ? 1 : 0;  // +axis face: the child with the larger coordinate is in front
    const float* face = child.data() + size_t(f) * child_cells * 4;
    auto at = [&](int32_t x, int32_t y, int32_t z) -> const float* {
      if (x >= cd[0] || y >= cd[1] || z >= cd[2]) return kZero;
      return face + (size_t(x) + size_t(cd[0]) * (size_t(y) + size_t(cd[1]) * size_t(z))) * 4;
    };
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int32_t z = 0; z < pd[2]; ++z)
      for (int32_t y = 0; y < pd[1]; ++y)
        for (int32_t x = 0; x < pd[0]; ++x) {
          float* o = out.data() + (size_t(f) * parent_cells + size_t(x) + size_t(pd[0]) * (size_t(y) + size_t(pd[1]) * size_t(z))) * 4;
          const int32_t p[3] = {x, y, z};
          for (int pair = 0; pair < 4; ++pair) {
            int32_t fc[3], bc[3];
            for (int a = 0; a < 3; ++a) fc[a] = bc[a] = 2 * p[a];
            fc[u] += pair & 1;
            bc[u] += pair & 1;
            fc[v] += (pair >> 1) & 1;
            bc[v] += (pair >> 1) & 1;
            fc[axis] += front_bit;
            bc[axis] += 1 - front_bit;
            const float* front = at(fc[0], fc[1], fc[2]);
            const float* back = at(bc[0], bc[1], bc[2]);
            for (int k = 0; k < 4; ++k) o[k] += 0.25f * (front[k] + (1.f - front[3]) * back[k]);
          }
        }
  }
  return out;
}

}  // namespace gibake
