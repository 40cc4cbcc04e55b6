// Loading the OpenVDB module (see vdb_module.h).
#include "io/vdb/vdb_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "io/vdb/module_api.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.0.0"
#endif
#ifndef GIBAKE_OPENVDB_MODULE
#define GIBAKE_OPENVDB_MODULE "libgibake_openvdb.so"
#endif

namespace gibake::vdb {
namespace {

struct Loaded {
  const ModuleApi* api = nullptr;
  std::string error;  // why `api` is null
};

std::string executable_folder() {
  char buffer[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof buffer - 1);
  if (n <= 0) return {};
  const std::string exe(buffer, size_t(n));
  const size_t slash = exe.find_last_of('/');
  return slash == std::string::npos ? std::string() : exe.substr(0, slash);
}

// Where the module may be, in order: installed beside the executable, in the executable's folder
// (a bundle), in the build tree this code was built in.
std::vector<std::string> candidates() {
  std::vector<std::string> out;
  const std::string exe = executable_folder();
#ifdef GIBAKE_OPENVDB_MODULE_INSTALLED
  if (!exe.empty()) out.push_back(exe + "/" GIBAKE_OPENVDB_MODULE_INSTALLED "/" GIBAKE_OPENVDB_MODULE);
#endif
  if (!exe.empty()) out.push_back(exe + "/" GIBAKE_OPENVDB_MODULE);
#ifdef GIBAKE_OPENVDB_MODULE_BUILT
  out.push_back(GIBAKE_OPENVDB_MODULE_BUILT "/" GIBAKE_OPENVDB_MODULE);
#endif
  return out;
}

Loaded open_module() {
  Loaded loaded;
  std::string tried;
  for (const std::string& path : candidates()) {
    tried += (tried.empty() ? "" : ", ") + path;
    if (access(path.c_str(), F_OK) != 0) continue;
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);  // never closed: OpenVDB's statics live on
    if (!handle) {
      const char* why = dlerror();
      loaded.error = "cannot load the OpenVDB module " + path + ": " + (why ? why : "unknown error");
      return loaded;
    }
    const auto entry = reinterpret_cast<gibake_openvdb_module_fn>(dlsym(handle, GIBAKE_OPENVDB_MODULE_ENTRY));
    const ModuleApi* api = entry ? entry() : nullptr;
    if (!api || api->abi != kModuleAbi || std::strcmp(api->version, GIBAKE_VERSION) != 0 ||
        api->grid_size != sizeof(Grid) || api->file_size != sizeof(File) ||
        api->query_size != sizeof(NearDistanceQuery)) {
      loaded.error = "the OpenVDB module " + path + " belongs to another build of gibake";
      return loaded;
    }
    loaded.api = api;
    return loaded;
  }
  loaded.error = "the OpenVDB module " GIBAKE_OPENVDB_MODULE " is missing (looked for " + tried + ")";
  return loaded;
}

// Loaded once per process, by the first caller; immutable after.
const Loaded& module() {
  static const Loaded loaded = open_module();
  return loaded;
}

// OpenVDB's linear transforms refuse a cell whose volume is within its tolerance of 0, and its
// level sets lose their precision well before that: a cell side below this is not written.
constexpr double kFinestCell = 1e-5;

// "" when every side of the cell `t` maps an index step to is a finite kFinestCell or more.
std::string cell_too_fine(const Transform& t) {
  for (int a = 0; a < 3; ++a) {
    const double side = std::fabs(t.uniform_scale * (t.pre_scale ? (*t.pre_scale)[size_t(a)] : 1.0));
    if (!(side >= kFinestCell) || !std::isfinite(side) || !std::isfinite(t.translate[size_t(a)])) {
      char text[160];
      std::snprintf(text, sizeof text, "a cell of %g m on axis %c, below the %g m an OpenVDB grid holds", side,
                    "xyz"[a], kFinestCell);
      return text;
    }
  }
  return {};
}

}  // namespace

Status write_file(const std::string& path, const File& file, const std::string& report_as) {
  for (const Grid& g : file.grids)
    if (const std::string why = cell_too_fine(g.transform); !why.empty())
      return Status::invalid(report_as, "grid " + g.name, why + " (glTF units are metres)");
  const Loaded& m = module();
  if (!m.api) return Status::error(ExitCode::RuntimeFailure, report_as, "OpenVDB", m.error);
  const std::string error = m.api->write_file(path, file);
  if (!error.empty()) return Status::io(report_as, "OpenVDB: " + error);
  return Status::ok();
}

Status near_distances(const NearDistanceQuery& query, std::vector<float>& band, const std::string& source,
                      const std::string& where) {
  Transform cell;
  cell.uniform_scale = query.voxel_size;
  if (const std::string why = cell_too_fine(cell); !why.empty())
    return Status::invalid(source, where,
                           "voxels too fine for the distance field: " + why +
                               " (glTF units are metres; --voxel-sdf off bakes without it)");
  const Loaded& m = module();
  if (!m.api) return Status::error(ExitCode::RuntimeFailure, source, where, m.error);
  const std::string error = m.api->near_distances(query, band);
  if (!error.empty()) return Status::error(ExitCode::RuntimeFailure, source, where, "OpenVDB: " + error);
  return Status::ok();
}

}  // namespace gibake::vdb
