// A minimal engine-side consumer: load a bake with gibake::loader and sample irradiance.
#include <cmath>
#include <cstdio>

#include "gibake/loader.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer <file.gibake>\n");
    return 1;
  }
  gibake::loader::BakeFile file;
  if (gibake::loader::Error error = file.open(argv[1])) {
    std::fprintf(stderr, "consumer: %s: %s\n", argv[1], error.message.c_str());
    return 3;
  }
  if (file.ddgi_volumes().empty()) {
    std::fprintf(stderr, "consumer: %s: no DDGI volume\n", argv[1]);
    return 3;
  }
  const gibake::loader::DdgiVolume& volume = file.ddgi_volumes().front();
  const gibake_ddgi_volume& desc = volume.desc();
  std::printf("%zu DDGI volume(s); the first: %u probes (%d x %d x %d), SH with %u coefficients\n",
              file.ddgi_volumes().size(), volume.probe_count(), desc.counts[0], desc.counts[1], desc.counts[2],
              volume.sh_coefficients());

  // Sample at the first volume's centre, facing each axis direction. sample_ddgi blends every volume
  // (a default bake has several: refined ones where the light changes), through the file's volume
  // index when it has one; with one volume it is that volume's sample_irradiance.
  const gibake::loader::Vec3 centre{0.5f * (desc.grid_min[0] + desc.grid_max[0]),
                                    0.5f * (desc.grid_min[1] + desc.grid_max[1]),
                                    0.5f * (desc.grid_min[2] + desc.grid_max[2])};
  const gibake::loader::Vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                           {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const char* names[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
  for (int i = 0; i < 6; ++i) {
    gibake::loader::Rgb e;
    file.sample_ddgi(centre, normals[i], e);
    if (!std::isfinite(e[0]) || !std::isfinite(e[1]) || !std::isfinite(e[2])) {
      std::fprintf(stderr, "consumer: non-finite irradiance\n");
      return 4;
    }
    std::printf("irradiance at centre facing %s: %.4g %.4g %.4g lux\n", names[i], e[0], e[1], e[2]);
  }
  return 0;
}
