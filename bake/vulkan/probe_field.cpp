#include "bake/vulkan/probe_field.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cstring>

namespace gibake {

namespace {

constexpr uint32_t kHeaderWords = 4;  // probe_field.glsl's kProbeFieldHeaderWords
constexpr uint32_t kNoIndex = 0xFFFFFFFFu;

uint64_t depth_texels(const loader::DdgiVolume& v) { return uint64_t(v.desc().depth_width) * v.desc().depth_height; }

// Pass one: every probe's state, offset and SH, volume after volume; each volume's first probe and
// first SH triplet go into its engine words 1 and 3.
void pack_probes(const std::vector<loader::DdgiVolume>& volumes, PackedProbeField& out,
                 std::vector<loader::GlslDdgiVolume>& glsl) {
  uint64_t probes = 0, sh_floats = 0;
  for (const loader::DdgiVolume& v : volumes) {
    probes += v.probe_count();
    sh_floats += uint64_t(v.probe_count()) * v.sh_coefficients() * 3;
  }
  sh_floats += sh_floats & 1;  // the depth texels' pairs start at an even float
  out.vec4s.reserve(size_t(probes) * 4);
  out.floats.reserve(size_t(sh_floats));
  uint64_t first_probe = 0;
  for (size_t i = 0; i < volumes.size(); ++i) {
    const loader::DdgiVolume& v = volumes[i];
    glsl[i] = v.glsl_volume();
    glsl[i].engine[1] = uint32_t(first_probe);
    glsl[i].engine[3] = uint32_t(out.floats.size() / 3);
    for (uint32_t p = 0; p < v.probe_count(); ++p) {
      out.words.push_back(v.state(p));
      const loader::Vec3 o = v.offset(p);
      out.vec4s.insert(out.vec4s.end(), {o[0], o[1], o[2], 0.f});
      for (uint32_t c = 0; c < v.sh_coefficients(); ++c)
        for (uint32_t k = 0; k < 3; ++k) out.floats.push_back(v.sh(p, c, k));
    }
    first_probe += v.probe_count();
  }
  out.floats.resize(size_t(sh_floats), 0.f);
}

// Pass two: each volume's irradiance atlas after the offsets (engine word 0, in vec4s) and its
// depth atlas after the SH (engine word 2, in float pairs), then every row of them in parallel.
void pack_atlases(const std::vector<loader::DdgiVolume>& volumes, PackedProbeField& out,
                  std::vector<loader::GlslDdgiVolume>& glsl) {
  uint64_t vec4s = out.vec4s.size() / 4, depth_pairs = out.floats.size() / 2;
  for (size_t i = 0; i < volumes.size(); ++i) {
    glsl[i].engine[0] = uint32_t(vec4s);
    glsl[i].engine[2] = uint32_t(depth_pairs);
    vec4s += uint64_t(volumes[i].desc().irradiance_width) * volumes[i].desc().irradiance_height;
    depth_pairs += depth_texels(volumes[i]);
  }
  out.vec4s.resize(size_t(vec4s) * 4);
  out.floats.resize(size_t(depth_pairs) * 2);
  struct Row {
    uint32_t volume, y;
    bool depth;
  };
  std::vector<Row> rows;
  for (uint32_t i = 0; i < volumes.size(); ++i) {
    for (uint32_t y = 0; y < volumes[i].desc().depth_height; ++y) rows.push_back({i, y, true});
    for (uint32_t y = 0; y < volumes[i].desc().irradiance_height; ++y) rows.push_back({i, y, false});
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size()), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t r = range.begin(); r < range.end(); ++r) {
      const Row& row = rows[r];
      const loader::DdgiVolume& v = volumes[row.volume];
      const gibake_ddgi_volume& d = v.desc();
      if (row.depth) {
        float* o = out.floats.data() + 2 * (size_t(glsl[row.volume].engine[2]) + size_t(row.y) * d.depth_width);
        for (uint32_t x = 0; x < d.depth_width; ++x, o += 2) {
          const std::array<float, 2> t = v.depth_texel(x, row.y);
          o[0] = t[0];
          o[1] = t[1];
        }
      } else {
        float* o = out.vec4s.data() + 4 * (size_t(glsl[row.volume].engine[0]) + size_t(row.y) * d.irradiance_width);
        for (uint32_t x = 0; x < d.irradiance_width; ++x, o += 4) {
          const std::array<float, 4> t = v.irradiance_texel(x, row.y);
          std::memcpy(o, t.data(), sizeof t);
        }
      }
    }
  });
}

// The file's volume index as stored (header word 1: where it starts, or kNoIndex), then each
// volume's rank in blend priority (header word 2: where they start).
void pack_index(const loader::BakeFile& file, PackedProbeField& out) {
  const int32_t index = file.ddgi_index().section();
  if (index >= 0) {
    out.words[1] = uint32_t(out.words.size());
    const uint64_t bytes = file.sections()[size_t(index)].size;
    const size_t first = out.words.size();
    out.words.resize(first + size_t((bytes + 3) / 4), 0u);
    std::memcpy(out.words.data() + first, file.section_data(uint32_t(index)), size_t(bytes));
  } else {
    out.words[1] = kNoIndex;
  }
  out.words[2] = uint32_t(out.words.size());
  std::vector<uint32_t> ranks(file.ddgi_volumes().size());
  for (uint32_t r = 0; r < ranks.size(); ++r) ranks[file.ddgi_priority()[r]] = r;
  out.words.insert(out.words.end(), ranks.begin(), ranks.end());
}

}  // namespace

PackedProbeField pack_probe_field(const loader::BakeFile& file) {
  const std::vector<loader::DdgiVolume>& volumes = file.ddgi_volumes();
  PackedProbeField out;
  out.words.assign(kHeaderWords, 0u);
  out.words[0] = uint32_t(volumes.size());
  std::vector<loader::GlslDdgiVolume> glsl(volumes.size());
  pack_probes(volumes, out, glsl);
  pack_atlases(volumes, out, glsl);
  for (uint32_t i : file.ddgi_priority()) out.volumes.push_back(glsl[i]);
  pack_index(file, out);
  return out;
}

}  // namespace gibake
