// libFuzzer target: the sky HDR reader (OpenEXR's RGBA interface behind load_sky_exr), then a few
// radiance look-ups on whatever loaded (the equirect wrap and clamp at the poles and the seam).
#include <cstdint>

#include "bake/scene/sky.h"
#include "tests/fuzz/fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = gibake::fuzz::scratch_path("sky.exr");
  if (!gibake::fuzz::write_input(path, data, size)) return 0;
  gibake::Sky sky;
  if (!gibake::load_sky_exr(path, sky).is_ok()) return 0;
  for (const gibake::kernels::float3 d : {gibake::kernels::float3{0.f, 1.f, 0.f}, gibake::kernels::float3{0.f, -1.f, 0.f},
                                          gibake::kernels::float3{0.f, 0.f, 1.f}, gibake::kernels::float3{0.6f, 0.f, -0.8f}})
    (void)sky.radiance(d);
  (void)sky.is_black();
  return 0;
}
