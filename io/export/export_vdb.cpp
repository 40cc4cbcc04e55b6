// VDB export (see export_vdb.h). OpenVDB includes stay in this file.
#include "io/export/export_vdb.h"

#include <openvdb/openvdb.h>

#include "io/output/bake_atomic.h"

namespace gibake {
namespace {

openvdb::math::Transform::Ptr probe_transform(const gibake_ddgi_volume& d) {
  openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(1.0);
  openvdb::Vec3d scale;
  for (int a = 0; a < 3; ++a) scale[a] = d.spacing[a] > 0.f ? double(d.spacing[a]) : 1.0;
  t->preScale(scale);
  t->postTranslate(openvdb::Vec3d(d.grid_min[0], d.grid_min[1], d.grid_min[2]));
  return t;
}

void add_volume_grids(const loader::DdgiVolume& v, const std::string& suffix, openvdb::GridPtrVec& grids) {
  const openvdb::math::Transform::Ptr xform = probe_transform(v.desc());
  auto irradiance = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  auto offset = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  auto state = openvdb::FloatGrid::create(0.f);
  auto ia = irradiance->getAccessor();
  auto oa = offset->getAccessor();
  auto sa = state->getAccessor();
  const float l0 = 3.14159265358979f * 0.282095f;
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    const auto c = v.probe_coord(p);
    const openvdb::Coord ijk(c[0], c[1], c[2]);
    ia.setValue(ijk, openvdb::Vec3s(l0 * v.sh(p, 0, 0), l0 * v.sh(p, 0, 1), l0 * v.sh(p, 0, 2)));
    const loader::Vec3 o = v.offset(p);
    oa.setValue(ijk, openvdb::Vec3s(o[0], o[1], o[2]));
    sa.setValue(ijk, v.state(p) == GIBAKE_PROBE_INACTIVE ? 1.f : 0.f);
  }
  const std::pair<openvdb::GridBase::Ptr, const char*> named[] = {
      {irradiance, "irradiance_l0"}, {offset, "offset"}, {state, "state"}};
  for (const auto& [grid, name] : named) {
    grid->setTransform(xform->copy());
    grid->setName(name + suffix);
    grids.push_back(grid);
  }
  irradiance->insertMeta("units", openvdb::StringMetadata("lux"));
  offset->insertMeta("units", openvdb::StringMetadata("m"));
  state->insertMeta("meaning", openvdb::StringMetadata("0 active, 1 inactive"));
}

// LPV cascade k as grids named like bake/lpv/lpv.h lpv_dense_grids(): lpv<k>_<c>_sh0 (float, band 0,
// cd) and lpv<k>_<c>_sh1 (vec3 (c3, c1, c2): band 1 as a vector), index space = cell coordinates,
// transform = scale(cell_size) then translate(grid_min + cell_size/2) (voxel centres on cell centres).
void add_lpv_grids(const loader::LpvCascade& c, openvdb::GridPtrVec& grids) {
  const gibake_lpv_cascade& d = c.desc();
  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(double(d.cell_size));
  const double half = 0.5 * double(d.cell_size);
  xform->postTranslate(openvdb::Vec3d(d.grid_min[0] + half, d.grid_min[1] + half, d.grid_min[2] + half));
  static const char* const kChannel[3] = {"r", "g", "b"};
  for (uint32_t ch = 0; ch < 3; ++ch) {
    auto sh0 = openvdb::FloatGrid::create(0.f);
    auto sh1 = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
    auto a0 = sh0->getAccessor();
    auto a1 = sh1->getAccessor();
    for (int32_t z = 0; z < d.dims[2]; ++z)
      for (int32_t y = 0; y < d.dims[1]; ++y)
        for (int32_t x = 0; x < d.dims[0]; ++x) {
          const uint32_t i = c.cell_index(x, y, z);
          const openvdb::Coord ijk(x, y, z);
          const float v0 = c.sh(i, ch, 0);
          const openvdb::Vec3s v1(c.sh(i, ch, 3), c.sh(i, ch, 1), c.sh(i, ch, 2));
          if (v0 != 0.f) a0.setValue(ijk, v0);
          if (v1 != openvdb::Vec3s(0.f)) a1.setValue(ijk, v1);
        }
    const std::string prefix = "lpv" + std::to_string(d.cascade_index) + "_" + kChannel[ch];
    sh0->setName(prefix + "_sh0");
    sh1->setName(prefix + "_sh1");
    for (const openvdb::GridBase::Ptr& g : {openvdb::GridBase::Ptr(sh0), openvdb::GridBase::Ptr(sh1)}) {
      g->setTransform(xform->copy());
      g->insertMeta("units", openvdb::StringMetadata("cd (L1 SH of radiant intensity, direction of travel)"));
      grids.push_back(g);
    }
  }
}

// Voxel-GI volume k, level 0 (format 1.3): vxgi<k>_<face> (Vec3SGrid, face px nx py ny pz nz) holds
// the radiance (cd/m^2, un-premultiplied) leaving each voxel through that face, vxgi<k>_alpha
// (FloatGrid) the largest alpha over the faces; index space = voxel coordinates, voxel centres on
// the bake's voxel centres.
void add_vxgi_grids(const loader::VxgiVolume& v, openvdb::GridPtrVec& grids) {
  const gibake_vxgi_volume& d = v.desc();
  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(double(d.voxel_size));
  const double half = 0.5 * double(d.voxel_size);
  xform->postTranslate(openvdb::Vec3d(d.grid_min[0] + half, d.grid_min[1] + half, d.grid_min[2] + half));
  static const char* const kFace[6] = {"px", "nx", "py", "ny", "pz", "nz"};
  const std::string prefix = "vxgi" + std::to_string(d.clipmap_index) + "_";
  auto alpha = openvdb::FloatGrid::create(0.f);
  auto aa = alpha->getAccessor();
  for (uint32_t f = 0; f < 6; ++f) {
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
    auto ga = grid->getAccessor();
    for (int32_t z = 0; z < d.dims[2]; ++z)
      for (int32_t y = 0; y < d.dims[1]; ++y)
        for (int32_t x = 0; x < d.dims[0]; ++x) {
          const loader::Rgba t = v.texel(0, f, x, y, z);
          if (!(t[3] > 0.f)) continue;
          const openvdb::Coord ijk(x, y, z);
          ga.setValue(ijk, openvdb::Vec3s(t[0] / t[3], t[1] / t[3], t[2] / t[3]));
          if (t[3] > aa.getValue(ijk)) aa.setValue(ijk, t[3]);
        }
    grid->setName(prefix + kFace[f]);
    grid->setTransform(xform->copy());
    grid->insertMeta("units", openvdb::StringMetadata("cd/m^2 (radiance leaving the voxel through this face)"));
    grids.push_back(grid);
  }
  alpha->setName(prefix + "alpha");
  alpha->setTransform(xform->copy());
  grids.push_back(alpha);
}

}  // namespace

Status export_vdb(const loader::BakeFile& file, const std::string& path) {
  if (file.ddgi_volumes().empty() && file.lpv_cascades().empty() && file.vxgi_volumes().empty())
    return Status::invalid("", "export", "the bake file has no DDGI volume, LPV cascade or voxel GI volume");
  openvdb::initialize();
  AtomicFile out;
  GIBAKE_TRY(out.begin(path));
  try {
    openvdb::GridPtrVec grids;
    for (size_t i = 0; i < file.ddgi_volumes().size(); ++i)
      add_volume_grids(file.ddgi_volumes()[i], i == 0 ? "" : "_" + std::to_string(i), grids);
    for (const loader::LpvCascade& c : file.lpv_cascades()) add_lpv_grids(c, grids);
    for (const loader::VxgiVolume& v : file.vxgi_volumes()) add_vxgi_grids(v, grids);
    openvdb::io::File vdb(out.temp_path());
    vdb.write(grids);
    vdb.close();
  } catch (const std::exception& e) {
    return Status::io(path, std::string("OpenVDB: ") + e.what());
  }
  return out.commit();
}

}  // namespace gibake
