// Voxel VDB export (see voxels_vdb.h). OpenVDB includes stay in this file.
#include "io/export/voxels_vdb.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <algorithm>
#include <cmath>

#include "io/output/bake_atomic.h"

namespace gibake {
namespace {

openvdb::math::Transform::Ptr voxel_transform(const std::array<float, 3>& origin, float size) {
  const double h = size;
  openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(h);
  t->postTranslate(openvdb::Vec3d(origin[0] + 0.5 * h, origin[1] + 0.5 * h, origin[2] + 0.5 * h));
  return t;
}

openvdb::Vec3s vec3(const float* v) { return openvdb::Vec3s(v[0], v[1], v[2]); }

template <class GridT>
void name_grid(GridT& grid, const std::string& name, const std::string& units, openvdb::GridClass cls,
               const openvdb::math::Transform::Ptr& xform) {
  grid.setName(name);
  grid.setTransform(xform->copy());
  grid.setGridClass(cls);
  if (!units.empty()) grid.insertMeta("units", openvdb::StringMetadata(units));
}

void add_surface_grids(const VoxelGrid& g, const openvdb::math::Transform::Ptr& xform, openvdb::GridPtrVec& out) {
  auto density = openvdb::FloatGrid::create(0.f);
  openvdb::Vec3SGrid::Ptr vec[4];
  for (auto& v : vec) v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  openvdb::FloatGrid::Ptr aniso[6];
  for (auto& a : aniso) a = openvdb::FloatGrid::create(0.f);
  auto da = density->getAccessor();
  auto a0 = vec[0]->getAccessor(), a1 = vec[1]->getAccessor(), a2 = vec[2]->getAccessor(), a3 = vec[3]->getAccessor();
  std::vector<openvdb::FloatGrid::Accessor> fa;
  for (auto& a : aniso) fa.push_back(a->getAccessor());
  for (const SurfaceVoxel& s : g.surface) {
    const openvdb::Coord c(s.ijk[0], s.ijk[1], s.ijk[2]);
    da.setValue(c, s.coverage);
    a0.setValue(c, vec3(s.albedo));
    a1.setValue(c, vec3(s.emission));
    a2.setValue(c, vec3(s.normal));
    a3.setValue(c, vec3(s.direct));
    for (int f = 0; f < 6; ++f) fa[size_t(f)].setValue(c, s.aniso[f]);
  }
  name_grid(*density, "density", "fraction of the voxel face covered (0..1)", openvdb::GRID_FOG_VOLUME, xform);
  out.push_back(density);
  const char* names[4] = {"albedo", "emission", "normal", "direct"};
  const char* units[4] = {"linear base colour", "cd/m^2", "unit vector", "lux"};
  for (int i = 0; i < 4; ++i) {
    name_grid(*vec[i], names[i], units[i], openvdb::GRID_UNKNOWN, xform);
    out.push_back(vec[i]);
  }
  vec[2]->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
  const char* faces[6] = {"aniso_px", "aniso_nx", "aniso_py", "aniso_ny", "aniso_pz", "aniso_nz"};
  for (int f = 0; f < 6; ++f) {
    name_grid(*aniso[f], faces[f], "share of the surface facing this way (0..1)", openvdb::GRID_UNKNOWN, xform);
    out.push_back(aniso[f]);
  }
}

void add_space_grids(const VoxelGrid& g, const openvdb::math::Transform::Ptr& xform, openvdb::GridPtrVec& out) {
  const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1));
  if (!g.sdf.empty()) {
    float far = 0.f;
    for (float v : g.sdf) far = std::max(far, std::fabs(v));
    auto sdf = openvdb::FloatGrid::create(far);
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, const_cast<float*>(g.sdf.data()));
    openvdb::tools::copyFromDense(dense, *sdf, -1.f);  // negative tolerance: every voxel stays active
    name_grid(*sdf, "sdf", "m", openvdb::GRID_LEVEL_SET, xform);
    out.push_back(sdf);
  }
  auto interior = openvdb::FloatGrid::create(0.f);
  auto ia = interior->getAccessor();
  for (int32_t z = 0; z < g.dims[2]; ++z)
    for (int32_t y = 0; y < g.dims[1]; ++y)
      for (int32_t x = 0; x < g.dims[0]; ++x)
        if (g.space[size_t(g.linear(x, y, z))] == uint8_t(VoxelSpace::Interior)) ia.setValue(openvdb::Coord(x, y, z), 1.f);
  name_grid(*interior, "interior", "1 = enclosed space unreachable from outside", openvdb::GRID_FOG_VOLUME, xform);
  out.push_back(interior);
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

openvdb::GridBase::Ptr extra_grid(const DenseGridExport& e) {
  const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(e.dims[0] - 1, e.dims[1] - 1, e.dims[2] - 1));
  openvdb::GridBase::Ptr out;
  if (e.channels == 1) {
    auto grid = openvdb::FloatGrid::create(0.f);
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, const_cast<float*>(e.values.data()));
    openvdb::tools::copyFromDense(dense, *grid, 0.f);
    out = grid;
  } else {
    std::vector<openvdb::Vec3s> v(e.values.size() / 3);
    for (size_t i = 0; i < v.size(); ++i) v[i] = vec3(&e.values[i * 3]);
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
    openvdb::tools::Dense<openvdb::Vec3s, openvdb::tools::LayoutXYZ> dense(box, v.data());
    openvdb::tools::copyFromDense(dense, *grid, openvdb::Vec3s(0.f));
    out = grid;
  }
  out->setName(e.name);
  out->setTransform(voxel_transform(e.origin, e.voxel_size));
  if (!e.units.empty()) out->insertMeta("units", openvdb::StringMetadata(e.units));
  return out;
}

openvdb::MetaMap file_metadata(const VoxelGrid& g, const VoxelVdbOptions& o) {
  openvdb::MetaMap meta;
  meta.insertMeta("gibake:origin", openvdb::Vec3SMetadata(openvdb::Vec3s(g.origin[0], g.origin[1], g.origin[2])));
  meta.insertMeta("gibake:voxel_size", openvdb::FloatMetadata(g.voxel_size));
  meta.insertMeta("gibake:dims", openvdb::Vec3IMetadata(openvdb::Vec3i(g.dims[0], g.dims[1], g.dims[2])));
  meta.insertMeta("gibake:units",
                  openvdb::StringMetadata("metres (+Y up, glTF world space); emission cd/m^2, direct lux; voxel "
                                          "(i,j,k) centre = origin + (ijk + 0.5) * voxel_size"));
  meta.insertMeta("gibake:settings", openvdb::StringMetadata(o.settings_json));
  meta.insertMeta("gibake:scene", openvdb::StringMetadata(o.scene));
  return meta;
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
  openvdb::initialize();
  AtomicFile out;
  GIBAKE_TRY(out.begin(path, options.inputs));
  try {
    const openvdb::math::Transform::Ptr xform = voxel_transform(grid.origin, grid.voxel_size);
    openvdb::GridPtrVec grids;
    add_surface_grids(grid, xform, grids);
    add_space_grids(grid, xform, grids);
    for (const DenseGridExport& e : extra) grids.push_back(extra_grid(e));
    openvdb::io::File vdb(out.temp_path());
    vdb.write(grids, file_metadata(grid, options));
    vdb.close();
  } catch (const std::exception& e) {
    return Status::io(path, std::string("OpenVDB: ") + e.what());
  }
  return out.commit();
}

}  // namespace gibake
