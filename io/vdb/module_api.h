// The entry point of the OpenVDB module (io/vdb/module/openvdb_module.cpp), shared by the module and
// its loader (vdb_module.cpp). Both come from one build: the loader checks the ABI number, gibake's
// version and the structs' sizes before it calls anything.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/vdb/vdb_grids.h"

namespace gibake::vdb {

constexpr uint32_t kModuleAbi = 1;

struct ModuleApi {
  uint32_t abi;
  const char* version;                      // GIBAKE_VERSION the module was built with
  size_t grid_size, file_size, query_size;  // sizeof(Grid), sizeof(File), sizeof(NearDistanceQuery)
  // Each returns an empty string on success, else what went wrong (OpenVDB's exceptions stay inside).
  std::string (*write_file)(const std::string& path, const File& file);
  // `band` gets one value per voxel of the query's grid: the distance (m) where OpenVDB's band is
  // active, +infinity elsewhere. Runs in the caller's TBB arena.
  std::string (*near_distances)(const NearDistanceQuery& query, std::vector<float>& band);
};

}  // namespace gibake::vdb

extern "C" {
// The module's one exported symbol.
typedef const gibake::vdb::ModuleApi* (*gibake_openvdb_module_fn)();
}
#define GIBAKE_OPENVDB_MODULE_ENTRY "gibake_openvdb_module"
