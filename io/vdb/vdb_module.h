// OpenVDB through its module (see vdb_grids.h): loaded on first use, from next to the executable
// (installed: <bindir>/../<libdir>/gibake/, or the executable's own folder), else from the build
// tree it was built in. A missing or mismatched module is an error naming `file` and what was tried.
#pragma once
#include <string>
#include <vector>

#include "io/status.h"
#include "io/vdb/vdb_grids.h"

namespace gibake::vdb {

// Writes `file` to `path` (a temporary the caller commits; see io/output/bake_atomic.h). Errors
// name `report_as` (the file the user asked for).
Status write_file(const std::string& path, const File& file, const std::string& report_as);

// OpenVDB's near distances (module_api.h); errors name `source` at `where`.
Status near_distances(const NearDistanceQuery& query, std::vector<float>& band, const std::string& source,
                      const std::string& where);

}  // namespace gibake::vdb
