// VDB export (see export_vdb.h). OpenVDB includes stay in this file.
#include "io/export/export_vdb.h"

#include <openvdb/openvdb.h>

#include "io/bake_atomic.h"

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

}  // namespace

Status export_vdb(const loader::BakeFile& file, const std::string& path) {
  if (file.ddgi_volumes().empty()) return Status::invalid("", "export", "the bake file has no DDGI volume");
  openvdb::initialize();
  AtomicFile out;
  GIBAKE_TRY(out.begin(path));
  try {
    openvdb::GridPtrVec grids;
    for (size_t i = 0; i < file.ddgi_volumes().size(); ++i)
      add_volume_grids(file.ddgi_volumes()[i], i == 0 ? "" : "_" + std::to_string(i), grids);
    openvdb::io::File vdb(out.temp_path());
    vdb.write(grids);
    vdb.close();
  } catch (const std::exception& e) {
    return Status::io(path, std::string("OpenVDB: ") + e.what());
  }
  return out.commit();
}

}  // namespace gibake
