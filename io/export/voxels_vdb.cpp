// Voxel VDB export (see voxels_vdb.h): the grids described in plain data (io/vdb/vdb_grids.h) and
// written by the OpenVDB module.
#include "io/export/voxels_vdb.h"

#include <algorithm>
#include <cmath>

#include "io/output/bake_atomic.h"
#include "io/vdb/vdb_module.h"

namespace gibake {
namespace {

// OpenVDB's index points are voxel centres: scale(voxel_size), then translate(origin + half a voxel).
vdb::Transform voxel_transform(const std::array<float, 3>& origin, float size) {
  vdb::Transform t;
  t.uniform_scale = size;
  const double h = size;
  for (int a = 0; a < 3; ++a) t.translate[size_t(a)] = origin[size_t(a)] + 0.5 * h;
  return t;
}

vdb::Grid named_grid(const std::string& name, int channels, const std::string& units, vdb::GridClass cls,
                     const vdb::Transform& xform) {
  vdb::Grid g;
  g.name = name;
  g.channels = channels;
  g.transform = xform;
  g.grid_class = cls;
  if (!units.empty()) g.meta.push_back(vdb::Meta::string("units", units));
  return g;
}

void add_surface_grids(const VoxelGrid& g, const vdb::Transform& xform, std::vector<vdb::Grid>& out) {
  vdb::Grid density =
      named_grid("density", 1, "fraction of the voxel face covered (0..1)", vdb::GridClass::FogVolume, xform);
  const char* names[4] = {"albedo", "emission", "normal", "direct"};
  const char* units[4] = {"linear base colour", "cd/m^2", "unit vector", "lux"};
  std::vector<vdb::Grid> vec;
  for (int i = 0; i < 4; ++i) vec.push_back(named_grid(names[i], 3, units[i], vdb::GridClass::Unknown, xform));
  vec[2].normalized_vectors = true;
  const char* faces[6] = {"aniso_px", "aniso_nx", "aniso_py", "aniso_ny", "aniso_pz", "aniso_nz"};
  std::vector<vdb::Grid> aniso;
  for (int f = 0; f < 6; ++f)
    aniso.push_back(
        named_grid(faces[f], 1, "share of the surface facing this way (0..1)", vdb::GridClass::Unknown, xform));
  for (const SurfaceVoxel& s : g.surface) {
    const std::array<int32_t, 3> c{s.ijk[0], s.ijk[1], s.ijk[2]};
    density.coords.push_back(c);
    density.values.push_back(s.coverage);
    const float* v[4] = {s.albedo, s.emission, s.normal, s.direct};
    for (int i = 0; i < 4; ++i) {
      vec[size_t(i)].coords.push_back(c);
      vec[size_t(i)].values.insert(vec[size_t(i)].values.end(), v[i], v[i] + 3);
    }
    for (int f = 0; f < 6; ++f) {
      aniso[size_t(f)].coords.push_back(c);
      aniso[size_t(f)].values.push_back(s.aniso[f]);
    }
  }
  out.push_back(std::move(density));
  for (vdb::Grid& v : vec) out.push_back(std::move(v));
  for (vdb::Grid& a : aniso) out.push_back(std::move(a));
}

void add_space_grids(const VoxelGrid& g, const vdb::Transform& xform, std::vector<vdb::Grid>& out) {
  if (!g.sdf.empty()) {
    vdb::Grid sdf = named_grid("sdf", 1, "m", vdb::GridClass::LevelSet, xform);
    for (float v : g.sdf) sdf.background = std::max(sdf.background, std::fabs(v));
    sdf.dense = true;
    sdf.dims = g.dims;
    sdf.tolerance = -1.f;  // every voxel stays active
    sdf.values = g.sdf;
    out.push_back(std::move(sdf));
  }
  vdb::Grid interior =
      named_grid("interior", 1, "1 = enclosed space unreachable from outside", vdb::GridClass::FogVolume, xform);
  for (int32_t z = 0; z < g.dims[2]; ++z)
    for (int32_t y = 0; y < g.dims[1]; ++y)
      for (int32_t x = 0; x < g.dims[0]; ++x)
        if (g.space[size_t(g.linear(x, y, z))] == uint8_t(VoxelSpace::Interior)) {
          interior.coords.push_back({x, y, z});
          interior.values.push_back(1.f);
        }
  out.push_back(std::move(interior));
}

Status check_extra(const std::string& path, const DenseGridExport& e, const std::vector<std::string>& taken) {
  auto bad = [&](const std::string& what) {
    return Status::error(ExitCode::BadArguments, path, "grid '" + e.name + "'", what);
  };
  if (e.name.empty()) return bad("an extra grid needs a name");
  if (std::find(taken.begin(), taken.end(), e.name) != taken.end()) return bad("the name is already used");
  if (e.channels != 1 && e.channels != 3) return bad("channels must be 1 or 3");
  if (!(e.voxel_size > 0.f) || !std::isfinite(e.voxel_size)) return bad("voxel size must be positive");
  double n = double(e.channels);
  for (int a = 0; a < 3; ++a) {
    if (e.dims[a] < 1) return bad("dims must be positive");
    n *= double(e.dims[a]);
  }
  if (double(e.values.size()) != n)
    return bad("holds " + std::to_string(e.values.size()) + " values, dims x channels = " + std::to_string(uint64_t(n)));
  return Status::ok();
}

vdb::Grid extra_grid(const DenseGridExport& e) {
  vdb::Grid g;
  g.name = e.name;
  g.channels = e.channels;
  g.transform = voxel_transform(e.origin, e.voxel_size);
  if (!e.units.empty()) g.meta.push_back(vdb::Meta::string("units", e.units));
  g.dense = true;
  g.dims = e.dims;
  g.tolerance = 0.f;  // zero values stay inactive
  g.values = e.values;
  return g;
}

std::vector<vdb::Meta> file_metadata(const VoxelGrid& g, const VoxelVdbOptions& o) {
  return {vdb::Meta::vec3s("gibake:origin", g.origin),
          vdb::Meta::number("gibake:voxel_size", g.voxel_size),
          vdb::Meta::vec3i("gibake:dims", g.dims),
          vdb::Meta::string("gibake:units",
                            "metres (+Y up, glTF world space); emission cd/m^2, direct lux; voxel "
                            "(i,j,k) centre = origin + (ijk + 0.5) * voxel_size"),
          vdb::Meta::string("gibake:settings", o.settings_json),
          vdb::Meta::string("gibake:scene", o.scene)};
}

}  // namespace

const std::vector<std::string>& voxel_vdb_grid_names() {
  static const std::vector<std::string> names{"density",  "albedo",   "emission", "normal",   "direct",
                                              "aniso_px", "aniso_nx", "aniso_py", "aniso_ny", "aniso_pz",
                                              "aniso_nz", "sdf",      "interior"};
  return names;
}

std::vector<DenseGridExport> vxgi_vdb_grids(const VxgiResult& vxgi) {
  static const char* const kFace[kVxgiFaces] = {"px", "nx", "py", "ny", "pz", "nz"};
  std::vector<DenseGridExport> out;
  for (size_t k = 0; k < vxgi.clipmaps.size(); ++k) {
    const VxgiClipmap& c = vxgi.clipmaps[k];
    if (c.levels.empty()) continue;
    const size_t cells = c.voxel_count();
    const std::vector<float>& level0 = c.levels[0];
    DenseGridExport alpha;
    alpha.name = "vxgi" + std::to_string(k) + "_alpha";
    alpha.origin = c.grid_min;
    alpha.voxel_size = c.voxel_size;
    alpha.dims = c.dims;
    alpha.values.assign(cells, 0.f);
    alpha.units = "opacity (largest over the six faces)";
    for (int f = 0; f < kVxgiFaces; ++f) {
      DenseGridExport g = alpha;
      g.name = "vxgi" + std::to_string(k) + "_" + kFace[f];
      g.channels = 3;
      g.values.assign(cells * 3, 0.f);
      g.units = "cd/m^2 (radiance leaving the voxel through this face)";
      for (size_t i = 0; i < cells; ++i) {
        const float* t = level0.data() + (size_t(f) * cells + i) * 4;
        if (!(t[3] > 0.f)) continue;
        for (int ch = 0; ch < 3; ++ch) g.values[i * 3 + size_t(ch)] = t[ch] / t[3];  // stored premultiplied
        alpha.values[i] = std::max(alpha.values[i], t[3]);
      }
      out.push_back(std::move(g));
    }
    out.push_back(std::move(alpha));
  }
  return out;
}

Status write_voxels_vdb(const std::string& path, const VoxelGrid& grid, const std::vector<DenseGridExport>& extra,
                        const VoxelVdbOptions& options) {
  if (grid.empty() || grid.space.size() != size_t(grid.linear(grid.dims[0] - 1, grid.dims[1] - 1, grid.dims[2] - 1)) + 1)
    return Status::error(ExitCode::RuntimeFailure, path, "voxels", "the voxel grid is empty or inconsistent");
  std::vector<std::string> taken = voxel_vdb_grid_names();
  for (const DenseGridExport& e : extra) {
    GIBAKE_TRY(check_extra(path, e, taken));
    taken.push_back(e.name);
  }
  vdb::File file;
  const vdb::Transform xform = voxel_transform(grid.origin, grid.voxel_size);
  add_surface_grids(grid, xform, file.grids);
  add_space_grids(grid, xform, file.grids);
  for (const DenseGridExport& e : extra) file.grids.push_back(extra_grid(e));
  file.meta = file_metadata(grid, options);
  AtomicFile out;
  GIBAKE_TRY(out.begin(path, options.inputs));
  GIBAKE_TRY(vdb::write_file(out.temp_path(), file, path));
  return out.commit();
}

}  // namespace gibake
