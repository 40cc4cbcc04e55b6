// libFuzzer target: open/validate (with and without checksums) and sample whatever loads; the
// second pass opens with probe-major tiles and every DDGI answer must equal the atlases' bit for bit.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "gibake/loader.hpp"

using namespace gibake::loader;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  for (bool checksums : {true, false}) {
    BakeFile file, rows;
    if (file.open_borrowed(data, size, LoadOptions{checksums, !checksums})) continue;
    const bool compare = !checksums && !rows.open_borrowed(data, size, LoadOptions{false, false});
    (void)file.metadata_json();
    for (const DdgiVolume& v : file.ddgi_volumes()) {
      const gibake_ddgi_volume& d = v.desc();
      const uint32_t probes = v.probe_count() < 64 ? v.probe_count() : 64;
      for (uint32_t p = 0; p < probes; ++p) {
        (void)v.sh_irradiance(p, {0.f, 0.f, 1.f});
        (void)v.probe_position(p);
        (void)v.stats(p);
      }
      (void)v.irradiance_texel(d.irradiance_width ? d.irradiance_width - 1 : 0, 0);
      (void)v.depth_texel(0, d.depth_height ? d.depth_height - 1 : 0);
      for (float t : {-0.5f, 0.f, 0.3f, 0.99f, 1.f, 1.5f}) {
        const Vec3 pos{d.grid_min[0] + t * (d.grid_max[0] - d.grid_min[0]),
                       d.grid_min[1] + t * (d.grid_max[1] - d.grid_min[1]),
                       d.grid_min[2] + t * (d.grid_max[2] - d.grid_min[2])};
        for (const Vec3& n : {Vec3{0.f, 1.f, 0.f}, Vec3{0.577f, -0.577f, 0.577f}}) {
          const Rgb e = v.sample_irradiance(pos, n);
          if (!compare) continue;
          const Rgb r = rows.ddgi_volumes()[size_t(&v - file.ddgi_volumes().data())].sample_irradiance(pos, n);
          if (std::memcmp(e.data(), r.data(), sizeof e) != 0) std::abort();
        }
      }
    }
    for (const LpvCascade& c : file.lpv_cascades()) {
      const gibake_lpv_cascade& d = c.desc();
      float sh[12];
      c.cell_sh(c.cell_count() - 1, sh);
      for (float t : {-0.5f, 0.f, 0.3f, 0.99f, 1.f, 1.5f}) {
        const Vec3 pos{d.grid_min[0] + t * float(d.dims[0]) * d.cell_size,
                       d.grid_min[1] + t * float(d.dims[1]) * d.cell_size,
                       d.grid_min[2] + t * float(d.dims[2]) * d.cell_size};
        (void)file.sample_lpv(pos, {0.f, 1.f, 0.f});
        (void)c.sample_irradiance(pos, {0.577f, -0.577f, 0.577f});
      }
    }
  }
  return 0;
}
