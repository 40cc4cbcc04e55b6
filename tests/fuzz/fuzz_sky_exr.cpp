// libFuzzer target: the sky HDR reader (OpenEXR behind load_sky_exr: float R, G, B, or the RGBA interface), then a few
// radiance look-ups on whatever loaded (the equirect wrap and clamp at the poles and the seam).
#include <ImfRgbaFile.h>

#include <cstdint>

#include "bake/scene/sky.h"
#include "tests/fuzz/fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = gibake::fuzz::scratch_path("sky.exr");
  if (!gibake::fuzz::write_input(path, data, size)) return 0;
  // A valid header may declare tens of millions of pixels in a few kilobytes (load_sky_exr takes up
  // to 2^28): decoding them is the same code on more pixels, and under the sanitizers it outlasts
  // the fuzz run's per-input timeout. Such headers are skipped; every smaller one is read.
  try {
    Imf::RgbaInputFile header(path.c_str());
    const Imath::Box2i dw = header.dataWindow();
    const long long w = static_cast<long long>(dw.max.x) - dw.min.x + 1,
                    h = static_cast<long long>(dw.max.y) - dw.min.y + 1;
    if (w > 0 && h > 0 && w * h > (1ll << 22)) return 0;
  } catch (...) {
    // load_sky_exr reports what OpenEXR refuses
  }
  gibake::Sky sky;
  if (!gibake::load_sky_exr(path, sky).is_ok()) return 0;
  for (const gibake::kernels::float3 d : {gibake::kernels::float3{0.f, 1.f, 0.f}, gibake::kernels::float3{0.f, -1.f, 0.f},
                                          gibake::kernels::float3{0.f, 0.f, 1.f}, gibake::kernels::float3{0.6f, 0.f, -0.8f}})
    (void)sky.radiance(d);
  (void)sky.is_black();
  return 0;
}
