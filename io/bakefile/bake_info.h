// `gibake info`: what a bake file holds, as text or JSON (docs/FORMAT.md).
#pragma once
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "gibake/loader.hpp"
#include "io/status.h"

namespace gibake {

// Opens and validates a bake file; loader errors become InvalidInput (IoFailure when unreadable),
// "<path>: <section>: <problem>". `probe_major_tiles`: for commands that sample the DDGI
// volumes on the CPU many times (loader::LoadOptions::probe_major_tiles).
Status open_bake_file(const std::string& path, loader::BakeFile& file, bool verify_checksums = true,
                      bool probe_major_tiles = false);

const char* probe_state_name(uint32_t state);  // "active", "inactive", "unknown"

struct InfoOptions {
  bool probes = false;  // list every probe
  bool json = false;
};

// The JSON report: {"version","file_size","input_hash","sections":[..],"metadata":{..},
// "ddgi":[{"grid_min",..,"probes":[{"index","coord","position","state","sh":[[r,g,b],..]}]}],
// "ddgi_index":{"section","grid_min","cell_size","dims","cell_count","volume_count","id_count",
// "longest_list"} (only with a volume index, 1.4)}.
nlohmann::json bake_info_json(const loader::BakeFile& file, bool probes);

Status bake_info(const std::string& path, const InfoOptions& options, std::ostream& out);

}  // namespace gibake
