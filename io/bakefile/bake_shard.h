// Shard files: one shard of a split DDGI bake (`gibake bake --shard I/N`) as a valid bake file
// whose sections 32..37 (gibake/format.h, docs/FORMAT.md "Shard files") say which shard of which
// bake it holds and carry what `gibake merge` needs of its probes. The shard with the global flag
// also carries the bake's LPV cascades, which the merge copies byte for byte.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "io/results/ddgi_shard.h"
#include "io/results/lpv_result.h"
#include "io/status.h"

namespace gibake {

// XXH3-64 of the canonical (sorted, compact) settings JSON: the settings part of a shard's identity.
uint64_t hash_settings(const std::string& settings_json);

// The shard sections of `shard` (info, probes, pass-0 SH, texels, depth tiles, bounce hits), appended
// to `out`, each in the group of the volume's info (its index in `out`). The shard's per-probe arrays
// are released as they are encoded (a shard file is written once), so they are never held twice.
void shard_sections(DdgiShard& shard, std::vector<RawSection>& out);

// Writes a shard file atomically: every volume's sections in order, `lpv` (the global shard only;
// encoded with `options`, as the complete bake would) and the metadata (the first volume's
// metadata_json plus a "shard" object). Releases the shards' per-probe arrays (shard_sections).
Status write_shard_file(const std::string& path, std::vector<DdgiShard>& volumes, const LpvResult* lpv,
                        const BakeFileOptions& options, const std::vector<std::string>& inputs);
// A shard of a bake of one volume (moved from).
Status write_shard_file(const std::string& path, DdgiShard& shard, const LpvResult* lpv,
                        const BakeFileOptions& options, const std::vector<std::string>& inputs);

// Reads and checks a shard file: integrity (checksums), one shard_info per volume in order whose
// blocks follow each other and whose range is shard_range()'s, every shard section once per volume
// (in its info's group) with the sizes the info implies. `lpv` receives the LPV sections of a
// global shard (groups relative to the list). Errors: InvalidInput naming the file (IoFailure when
// unreadable).
Status read_shard_volumes(const std::string& path, std::vector<DdgiShard>& volumes, std::vector<RawSection>* lpv);
// The same, the first volume only.
Status read_shard_file(const std::string& path, DdgiShard& shard, std::vector<RawSection>* lpv);

// gibake info: {"index","count","probe_begin","probe_end","input_hash","settings_hash",...} of a
// shard file; null for any other file.
nlohmann::json shard_info_json(const loader::BakeFile& file);

}  // namespace gibake
