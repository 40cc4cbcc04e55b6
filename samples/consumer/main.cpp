// A minimal engine-side consumer: load a bake with gibake::loader, sample irradiance on the CPU and
// lay out the buffers the fragment shader (ddgi_shading.frag) reads on the GPU.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "gibake/loader.hpp"

// The buffers ddgi_shading.frag reads, every volume's data after the one before: upload each as it
// is (bindings 0-8) and push volume_count and has_index. Each volume's engine words say where its
// data starts, so one set of buffers serves every volume. Per-probe data is kept for the probes the
// file stores (a sparse volume's, in slot order), so a near-surface volume costs what its file does.
struct ShaderBuffers {
  std::vector<float> sh, offsets, depth;  // [probe][9][rgb]; [probe] xyz0; [texel] mean, mean^2
  std::vector<float> irradiance;          // [texel] rgba (lux), binding 7; one zero texel when no volume has one
  std::vector<uint32_t> states;
  std::vector<uint32_t> slots;  // binding 8: each sparse volume's slot map; one zero word when none
  std::vector<gibake::loader::GlslDdgiVolume> volumes;  // in BakeFile::ddgi_priority() order
  std::vector<uint32_t> index, ranks;                   // the ddgi_volume_index payload; each volume's rank
  uint32_t volume_count = 0, has_index = 0;
};

ShaderBuffers shader_buffers(const gibake::loader::BakeFile& file) {
  ShaderBuffers b;
  std::vector<gibake::loader::GlslDdgiVolume> in_file_order;
  for (const gibake::loader::DdgiVolume& v : file.ddgi_volumes()) {
    gibake::loader::GlslDdgiVolume g = v.glsl_volume();
    const gibake_ddgi_volume& d = v.desc();
    g.engine[0] = uint32_t(b.irradiance.size() / 4);
    g.engine[1] = uint32_t(b.states.size());
    g.engine[2] = uint32_t(b.depth.size() / 2);
    g.engine[3] = uint32_t(b.slots.size());
    in_file_order.push_back(g);
    for (uint32_t p = 0; p < v.probe_count(); ++p) {
      if (v.sparse()) b.slots.push_back(v.slot(p));
      if (v.slot(p) == GIBAKE_PROBE_SLOT_NONE) continue;  // not stored: the sampler skips it
      for (uint32_t c = 0; c < 9; ++c)
        for (uint32_t k = 0; k < 3; ++k) b.sh.push_back(c < v.sh_coefficients() ? v.sh(p, c, k) : 0.f);
      b.states.push_back(v.state(p));
      const gibake::loader::Vec3 o = v.offset(p);
      b.offsets.insert(b.offsets.end(), {o[0], o[1], o[2], 0.f});
    }
    for (uint32_t y = 0; y < d.depth_height; ++y)
      for (uint32_t x = 0; x < d.depth_width; ++x) {
        const std::array<float, 2> t = v.depth_texel(x, y);
        b.depth.insert(b.depth.end(), {t[0], t[1]});
      }
    for (uint32_t y = 0; y < d.irradiance_height; ++y)
      for (uint32_t x = 0; x < d.irradiance_width; ++x) {
        // As stored: an RGB9E5 texel (format 1.5) before its volume's irradiance_scale, which the
        // sampler applies (GibakeDdgiVolume's spacing.w), as an E5B9G9R9 texture's texelFetch reads it.
        std::array<float, 4> t = v.irradiance_texel(x, y);
        const float scale = g.spacing[3];
        for (int k = 0; k < 3 && scale > 0.f; ++k) t[size_t(k)] /= scale;  // exact: a power of two
        b.irradiance.insert(b.irradiance.end(), t.begin(), t.end());
      }
  }
  if (b.irradiance.empty()) b.irradiance.assign(4, 0.f);  // a buffer must not be empty
  if (b.slots.empty()) b.slots.assign(1, 0u);
  b.ranks.resize(in_file_order.size());
  for (uint32_t rank = 0; rank < file.ddgi_priority().size(); ++rank) {
    b.volumes.push_back(in_file_order[file.ddgi_priority()[rank]]);
    b.ranks[file.ddgi_priority()[rank]] = rank;
  }
  b.volume_count = uint32_t(b.volumes.size());
  const int32_t section = file.ddgi_index().section();
  b.has_index = section >= 0 ? 1u : 0u;
  b.index.assign(1, 0u);  // a buffer must not be empty
  if (section >= 0) {
    b.index.resize(size_t(file.sections()[size_t(section)].size) / 4);
    std::memcpy(b.index.data(), file.section_data(uint32_t(section)), b.index.size() * 4);
  }
  return b;
}

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
  const gibake::loader::Vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
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

  const ShaderBuffers buffers = shader_buffers(file);
  std::printf("shader buffers: %zu SH floats, %zu probes, %zu depth texels, %zu irradiance texels, %u volumes, %s\n",
              buffers.sh.size(), buffers.states.size(), buffers.depth.size() / 2, buffers.irradiance.size() / 4,
              buffers.volume_count, buffers.has_index ? "indexed" : "no index: blended over every volume");
  return 0;
}
