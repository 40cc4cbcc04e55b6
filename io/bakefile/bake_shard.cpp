// Shard files (see bake_shard.h).
#include "io/bakefile/bake_shard.h"

#include <xxhash.h>

#include <cstdio>
#include <cstring>
#include <type_traits>

#include "gibake/format.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/input_digest.h"
#include "io/output/bake_atomic.h"

namespace gibake {
namespace {

constexpr uint64_t kIrrFloats = uint64_t(kIrradianceTexels) * kIrradianceTexels * 3;
constexpr uint64_t kDepthFloats = uint64_t(kShardDepthTile) * kShardDepthTile * 2;

template <typename T>
RawSection struct_section(uint32_t type, const T* values, size_t n) {
  RawSection s;
  s.type = type;
  s.format = GIBAKE_FORMAT_STRUCT;
  s.count = n;
  s.bytes.resize(n * sizeof(T));
  if (n) std::memcpy(s.bytes.data(), values, n * sizeof(T));
  return s;
}

// The values as an f32 section; `values` is released.
RawSection float_section(uint32_t type, std::vector<float>& values) {
  RawSection s;
  s.type = type;
  s.format = GIBAKE_FORMAT_F32;
  s.count = values.size();
  s.bytes.resize(values.size() * 4);
  if (!values.empty()) std::memcpy(s.bytes.data(), values.data(), s.bytes.size());
  std::vector<float>().swap(values);
  return s;
}

// What a shard (DdgiShard) and its info record (gibake_shard_info) both hold under the same names,
// handed to `f` in pairs (the shard's, the record's): one list for writing the record and reading it.
template <class Shard, class Info, class F>
void shared_fields(Shard& sh, Info& in, F f) {
  f(sh.input_hash, in.input_hash);
  f(sh.settings_hash, in.settings_hash);
  f(sh.sh_format, in.sh_format);
  f(sh.atlas_format, in.atlas_format);
  f(sh.closed_inside, in.closed_inside);
  f(sh.closed_inside_but_active, in.closed_inside_but_active);
  f(sh.closed_inactive_outside, in.closed_inactive_outside);
  f(sh.first_block, in.first_block);
  f(sh.atlas_planes_per_row, in.volume.atlas_planes_per_row);  // int in the shard, uint32_t in the file
  f(sh.irradiance_width, in.volume.irradiance_width);
  f(sh.irradiance_height, in.volume.irradiance_height);
  f(sh.depth_width, in.volume.depth_width);
  f(sh.depth_height, in.volume.depth_height);
}

gibake_shard_info encode_info(const DdgiShard& sh) {
  gibake_shard_info in{};
  gibake_ddgi_volume& v = in.volume;
  v = ddgi_volume_record(sh.desc);
  shared_fields(sh, in, [](const auto& s, auto& i) { i = std::decay_t<decltype(i)>(s); });
  in.shard_index = sh.range.index;
  in.shard_count = sh.range.count;
  in.probe_begin = sh.range.begin;
  in.probe_end = sh.range.end;
  in.flags = (sh.probe_gather ? GIBAKE_SHARD_FLAG_BOUNCE_HITS : 0u) | (sh.global ? GIBAKE_SHARD_FLAG_GLOBAL : 0u) |
             (sh.closed_checked ? GIBAKE_SHARD_FLAG_CLOSED_CHECKED : 0u);
  in.bounce_hit_count = sh.bounce_hits.size() / kShardHitFloats;
  in.volume_index = sh.volume;
  in.volume_count = sh.volumes;
  in.total_blocks = sh.total_blocks ? sh.total_blocks : sh.first_block + probe_blocks(v.probe_count);
  return in;
}

// The info's description of the grid back into the shard, with every check a merge relies on.
Status decode_info(const std::string& path, const gibake_shard_info& in, DdgiShard& sh) {
  auto bad = [&](const std::string& what) { return Status::invalid(path, "shard_info", what); };
  const gibake_ddgi_volume& v = in.volume;
  uint64_t product = 1;
  for (int a = 0; a < 3; ++a) {
    if (v.counts[a] < 1 || v.counts[a] > 65536) return bad("probe counts out of range");
    product *= uint64_t(v.counts[a]);
    sh.desc.grid_min[a] = v.grid_min[a];
    sh.desc.grid_max[a] = v.grid_max[a];
    sh.desc.spacing[a] = v.spacing[a];
    sh.desc.counts[a] = v.counts[a];
  }
  if (product != v.probe_count || product > (uint64_t(1) << 26)) return bad("probe_count is not the product of counts");
  if ((v.sh_order != 1 && v.sh_order != 2) || v.sh_coefficients != (v.sh_order + 1) * (v.sh_order + 1))
    return bad("bad SH order or coefficient count");
  if (in.shard_count < 1 || in.shard_index >= in.shard_count) return bad("shard index out of range");
  // The volume's place among the bake's (read_shard_volumes checks it against the other infos).
  if (in.volume_count < 1 || in.volume_index >= in.volume_count) return bad("volume index out of range");
  if (uint64_t(in.first_block) + probe_blocks(v.probe_count) > in.total_blocks)
    return bad("the volume's probe blocks lie outside the bake's");
  const ShardRange expect = shard_range(in.shard_index, in.shard_count, v.probe_count, in.first_block, in.total_blocks);
  if (in.probe_begin != expect.begin || in.probe_end != expect.end)
    return bad("probe range [" + std::to_string(in.probe_begin) + ", " + std::to_string(in.probe_end) +
               ") is not shard " + std::to_string(in.shard_index) + " of " + std::to_string(in.shard_count) + "'s");
  if (v.atlas_planes_per_row < 1 || int32_t(v.atlas_planes_per_row) > v.counts[1]) return bad("bad atlas layout");
  if (in.sh_format > 2 || in.atlas_format > 3) return bad("unknown storage format");
  sh.desc.sh_order = int32_t(v.sh_order);
  sh.desc.max_distance = v.max_distance;
  shared_fields(sh, in, [](auto& s, const auto& i) { s = std::decay_t<decltype(s)>(i); });
  sh.range = expect;
  sh.volume = in.volume_index;
  sh.volumes = in.volume_count;
  sh.total_blocks = in.total_blocks;
  sh.probe_gather = in.flags & GIBAKE_SHARD_FLAG_BOUNCE_HITS;
  sh.global = in.flags & GIBAKE_SHARD_FLAG_GLOBAL;
  sh.closed_checked = in.flags & GIBAKE_SHARD_FLAG_CLOSED_CHECKED;
  return Status::ok();
}

// Section `type` of the file in group `group` (a volume's shard_info; any group: UINT32_MAX):
// exactly one, in `format`, with `count` elements.
Status find_section(const std::string& path, const loader::BakeFile& f, uint32_t type, uint32_t format, uint64_t count,
                    uint64_t element, const uint8_t*& data, uint32_t group = UINT32_MAX) {
  data = nullptr;
  const char* name = loader::section_type_name(type);
  for (uint32_t i = 0; i < f.sections().size(); ++i) {
    const gibake_section_entry& e = f.sections()[i];
    if (e.type != type || (group != UINT32_MAX && e.group != group)) continue;
    if (data) return Status::invalid(path, name, "appears twice");
    if (e.format != format || e.count != count)
      return Status::invalid(path, name,
                             "expected " + std::to_string(count) + " elements of format " +
                                 loader::element_format_name(format) + ", found " + std::to_string(e.count) + " of " +
                                 loader::element_format_name(e.format));
    if (e.size != count * element) return Status::invalid(path, name, "size does not match the count");
    data = f.section_data(i);
  }
  if (!data && count > 0) return Status::invalid(path, name, "missing");
  return Status::ok();
}

void read_floats(const uint8_t* data, uint64_t n, std::vector<float>& out) {
  out.resize(n);
  if (n) std::memcpy(out.data(), data, n * 4);
}

// What a shard probe (DdgiShardProbe) and its record in the file (gibake_shard_probe) hold under
// the same names, copied either way: the offset, the ray statistics and the counters.
template <class To, class From>
void copy_probe_fields(To& to, const From& from) {
  std::memcpy(to.offset, from.offset, sizeof to.offset);
  to.stats = {from.stats.rays, from.stats.relative_error, from.stats.nearest_front, from.stats.backface_fraction};
  to.integrated_rays = from.integrated_rays;
  to.bounce_hits = from.bounce_hits;
  to.primary_rays = from.primary_rays;
  to.shadow_rays = from.shadow_rays;
  to.bounce_rays = from.bounce_rays;
  to.relocation_rays = from.relocation_rays;
}

// The volume's sections: those in group `group` (its shard_info's index).
Status decode_probes(const std::string& path, const loader::BakeFile& f, DdgiShard& sh, uint64_t hit_count,
                     uint32_t group) {
  const uint64_t n = sh.range.end - sh.range.begin;
  const uint8_t* data = nullptr;
  GIBAKE_TRY(find_section(path, f, GIBAKE_SECTION_SHARD_PROBES, GIBAKE_FORMAT_STRUCT, n, sizeof(gibake_shard_probe), data,
                          group));
  sh.probes.resize(n);
  uint64_t hits = 0;
  for (uint64_t i = 0; i < n; ++i) {
    gibake_shard_probe p;
    std::memcpy(&p, data + i * sizeof p, sizeof p);
    DdgiShardProbe& q = sh.probes[i];
    copy_probe_fields(q, p);
    q.inactive = p.flags & GIBAKE_SHARD_PROBE_INACTIVE;
    q.enclosed = p.flags & GIBAKE_SHARD_PROBE_ENCLOSED;
    q.sky_only = p.flags & GIBAKE_SHARD_PROBE_SKY_ONLY;
    q.moved = p.flags & GIBAKE_SHARD_PROBE_MOVED;
    hits += p.bounce_hits;
  }
  if (hits != hit_count) return Status::invalid(path, "shard_probes", "bounce-hit counts do not add up to the info's");
  const uint64_t coefs = uint64_t(sh.desc.sh_coefficients());
  GIBAKE_TRY(find_section(path, f, GIBAKE_SECTION_SHARD_SH0, GIBAKE_FORMAT_F32, n * coefs * 3, 4, data, group));
  read_floats(data, n * coefs * 3, sh.sh0);
  GIBAKE_TRY(find_section(path, f, GIBAKE_SECTION_SHARD_IRRADIANCE, GIBAKE_FORMAT_F32, n * kIrrFloats, 4, data, group));
  read_floats(data, n * kIrrFloats, sh.irradiance);
  GIBAKE_TRY(find_section(path, f, GIBAKE_SECTION_SHARD_DEPTH, GIBAKE_FORMAT_F32, n * kDepthFloats, 4, data, group));
  read_floats(data, n * kDepthFloats, sh.depth_tiles);
  GIBAKE_TRY(
      find_section(path, f, GIBAKE_SECTION_SHARD_BOUNCE_HITS, GIBAKE_FORMAT_F32, hit_count * kShardHitFloats, 4, data, group));
  read_floats(data, hit_count * kShardHitFloats, sh.bounce_hits);
  return Status::ok();
}

// The LPV sections of a global shard, in file order, groups relative to the list.
void collect_lpv(const loader::BakeFile& f, std::vector<RawSection>& out) {
  std::vector<int64_t> index_of(f.sections().size(), -1);
  for (uint32_t i = 0; i < f.sections().size(); ++i) {
    const gibake_section_entry& e = f.sections()[i];
    if (e.type != GIBAKE_SECTION_LPV_CASCADE && e.type != GIBAKE_SECTION_LPV_SH) continue;
    index_of[i] = int64_t(out.size());
    RawSection r;
    r.type = e.type;
    r.format = e.format;
    r.count = e.count;
    r.group = uint32_t(e.group < index_of.size() && index_of[e.group] >= 0 ? index_of[e.group] : 0);
    const uint8_t* d = f.section_data(i);
    r.bytes.assign(d, d + e.size);
    out.push_back(std::move(r));
  }
}

}  // namespace

uint64_t hash_settings(const std::string& settings_json) {
  std::string canonical = settings_json;
  try {
    canonical = nlohmann::json::parse(settings_json).dump();
  } catch (const nlohmann::json::exception&) {
  }
  return XXH3_64bits(canonical.data(), canonical.size());
}

void shard_sections(DdgiShard& sh, std::vector<RawSection>& out) {
  const gibake_shard_info info = encode_info(sh);
  const size_t first = out.size();
  out.push_back(struct_section(GIBAKE_SECTION_SHARD_INFO, &info, 1));
  std::vector<gibake_shard_probe> probes(sh.probes.size());
  for (size_t i = 0; i < probes.size(); ++i) {
    const DdgiShardProbe& q = sh.probes[i];
    gibake_shard_probe& p = probes[i];
    copy_probe_fields(p, q);
    p.flags = (q.inactive ? GIBAKE_SHARD_PROBE_INACTIVE : 0u) | (q.enclosed ? GIBAKE_SHARD_PROBE_ENCLOSED : 0u) |
              (q.sky_only ? GIBAKE_SHARD_PROBE_SKY_ONLY : 0u) | (q.moved ? GIBAKE_SHARD_PROBE_MOVED : 0u);
  }
  out.push_back(struct_section(GIBAKE_SECTION_SHARD_PROBES, probes.data(), probes.size()));
  std::vector<DdgiShardProbe>().swap(sh.probes);
  out.push_back(float_section(GIBAKE_SECTION_SHARD_SH0, sh.sh0));
  out.push_back(float_section(GIBAKE_SECTION_SHARD_IRRADIANCE, sh.irradiance));
  out.push_back(float_section(GIBAKE_SECTION_SHARD_DEPTH, sh.depth_tiles));
  out.push_back(float_section(GIBAKE_SECTION_SHARD_BOUNCE_HITS, sh.bounce_hits));
  for (size_t i = first; i < out.size(); ++i) out[i].group = uint32_t(first);  // the volume's info
}

Status write_shard_file(const std::string& path, std::vector<DdgiShard>& volumes, const LpvResult* lpv,
                        const BakeFileOptions& options, const std::vector<std::string>& inputs) {
  std::vector<RawSection> extra;
  const DdgiShard& first = volumes.front();
  nlohmann::json meta = nlohmann::json::parse(first.metadata_json);
  meta["shard"] = {{"index", first.range.index},
                   {"count", first.range.count},
                   {"probes", {first.range.begin, first.range.end}},
                   {"settings_hash", hash_text(first.settings_hash)},
                   {"global_volumes", first.global}};
  if (volumes.size() > 1) {
    nlohmann::json ranges = nlohmann::json::array();
    for (const DdgiShard& v : volumes) ranges.push_back({v.range.begin, v.range.end});
    meta["shard"]["volume_probes"] = ranges;
  }
  const uint64_t input_hash = first.input_hash;
  for (DdgiShard& v : volumes) shard_sections(v, extra);
  BakeOutputs outputs;
  outputs.lpv = lpv;
  outputs.metadata_json = meta.dump();
  outputs.input_hash = input_hash;
  outputs.extra = &extra;
  return write_bake_file(path, outputs, options, inputs);
}

Status write_shard_file(const std::string& path, DdgiShard& shard, const LpvResult* lpv,
                        const BakeFileOptions& options, const std::vector<std::string>& inputs) {
  std::vector<DdgiShard> one(1);
  one[0] = std::move(shard);
  return write_shard_file(path, one, lpv, options, inputs);
}

Status read_shard_volumes(const std::string& path, std::vector<DdgiShard>& volumes, std::vector<RawSection>* lpv) {
  volumes.clear();
  loader::BakeFile f;
  GIBAKE_TRY(open_bake_file(path, f));
  std::vector<uint32_t> infos;  // section indices of the shard_info sections, in file order
  for (uint32_t i = 0; i < f.sections().size(); ++i)
    if (f.sections()[i].type == GIBAKE_SECTION_SHARD_INFO) infos.push_back(i);
  if (infos.empty()) return Status::invalid(path, "shard_info", "not a shard file (no shard_info section)");
  volumes.resize(infos.size());
  uint32_t blocks = 0;  // the blocks of the volumes before
  for (size_t k = 0; k < infos.size(); ++k) {
    const gibake_section_entry& e = f.sections()[infos[k]];
    if (e.format != GIBAKE_FORMAT_STRUCT || e.count != 1 || e.size != sizeof(gibake_shard_info))
      return Status::invalid(path, "shard_info", "expected one gibake_shard_info");
    gibake_shard_info info;
    std::memcpy(&info, f.section_data(infos[k]), sizeof info);
    DdgiShard& shard = volumes[k];
    GIBAKE_TRY(decode_info(path, info, shard));
    // One info per volume, in order, their blocks one after the other, the same shard of one bake.
    if (shard.volume != k || shard.volumes != infos.size() || shard.first_block != blocks ||
        (k > 0 && (shard.total_blocks != volumes[0].total_blocks || shard.range.index != volumes[0].range.index ||
                   shard.range.count != volumes[0].range.count || shard.settings_hash != volumes[0].settings_hash)))
      return Status::invalid(path, "shard_info", "volume " + std::to_string(k) + "'s info does not follow the one before");
    blocks += probe_blocks(uint32_t(shard.desc.probe_count()));
    if (info.input_hash != f.header().input_hash)
      return Status::invalid(path, "shard_info", "input hash differs from the file header's");
    GIBAKE_TRY(decode_probes(path, f, shard, info.bounce_hit_count, infos[k]));
  }
  if (blocks != volumes[0].total_blocks)
    return Status::invalid(path, "shard_info", "the volumes' probe blocks do not add up to the bake's");
  std::string metadata;
  try {
    nlohmann::json meta = nlohmann::json::parse(f.metadata_json());
    if (!meta.is_object() || !meta.contains("settings")) return Status::invalid(path, "metadata", "no settings");
    if (hash_settings(meta["settings"].dump()) != volumes[0].settings_hash)
      return Status::invalid(path, "metadata", "settings do not match the shard's settings hash");
    meta.erase("shard");
    metadata = meta.dump();
  } catch (const nlohmann::json::exception& e) {
    return Status::invalid(path, "metadata", std::string("invalid JSON: ") + e.what());
  }
  for (DdgiShard& v : volumes) v.metadata_json = metadata;
  if (lpv) {
    lpv->clear();
    if (volumes[0].global) collect_lpv(f, *lpv);
  }
  return Status::ok();
}

Status read_shard_file(const std::string& path, DdgiShard& shard, std::vector<RawSection>* lpv) {
  std::vector<DdgiShard> volumes;
  shard = DdgiShard{};
  GIBAKE_TRY(read_shard_volumes(path, volumes, lpv));
  shard = std::move(volumes[0]);
  return Status::ok();
}

nlohmann::json shard_info_json(const loader::BakeFile& f) {
  for (uint32_t i = 0; i < f.sections().size(); ++i) {
    const gibake_section_entry& e = f.sections()[i];
    if (e.type != GIBAKE_SECTION_SHARD_INFO || e.size != sizeof(gibake_shard_info)) continue;
    gibake_shard_info in;
    std::memcpy(&in, f.section_data(i), sizeof in);
    return {{"index", in.shard_index},
            {"count", in.shard_count},
            {"probe_begin", in.probe_begin},
            {"probe_end", in.probe_end},
            {"probe_count", in.volume.probe_count},
            {"counts", {in.volume.counts[0], in.volume.counts[1], in.volume.counts[2]}},
            {"input_hash", hash_text(in.input_hash)},
            {"settings_hash", hash_text(in.settings_hash)},
            {"gather", (in.flags & GIBAKE_SHARD_FLAG_BOUNCE_HITS) ? "probes" : "path"},
            {"bounce_hits", in.bounce_hit_count},
            {"global_volumes", bool(in.flags & GIBAKE_SHARD_FLAG_GLOBAL)},
            {"volumes", in.volume_count}};
  }
  return nullptr;
}

}  // namespace gibake
