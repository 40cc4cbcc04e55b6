// VDB export (see export_vdb.h): the grids described in plain data (io/vdb/vdb_grids.h) and written
// by the OpenVDB module.
#include "io/export/export_vdb.h"

#include <algorithm>
#include <array>

#include "io/output/bake_atomic.h"
#include "io/vdb/vdb_module.h"

namespace gibake {
namespace {

// Index space = probe coordinates: scale(spacing) (1 on a 1-probe axis), then translate(grid_min).
vdb::Transform probe_transform(const gibake_ddgi_volume& d) {
  vdb::Transform t;
  std::array<double, 3> scale;
  for (int a = 0; a < 3; ++a) scale[size_t(a)] = d.spacing[a] > 0.f ? double(d.spacing[a]) : 1.0;
  t.pre_scale = scale;
  for (int a = 0; a < 3; ++a) t.translate[size_t(a)] = d.grid_min[a];
  return t;
}

// Voxel centres on cell centres: scale(size), then translate(grid_min + half a cell).
vdb::Transform cell_transform(float size, const float* grid_min) {
  vdb::Transform t;
  t.uniform_scale = size;
  const double half = 0.5 * double(size);
  for (int a = 0; a < 3; ++a) t.translate[size_t(a)] = grid_min[a] + half;
  return t;
}

vdb::Grid grid(const std::string& name, int channels, const vdb::Transform& xform) {
  vdb::Grid g;
  g.name = name;
  g.channels = channels;
  g.transform = xform;
  return g;
}

void add_volume_grids(const loader::DdgiVolume& v, const std::string& suffix, std::vector<vdb::Grid>& grids) {
  const vdb::Transform xform = probe_transform(v.desc());
  vdb::Grid irradiance = grid("irradiance_l0" + suffix, 3, xform), offset = grid("offset" + suffix, 3, xform),
            state = grid("state" + suffix, 1, xform);
  const float l0 = 3.14159265358979f * 0.282095f;
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    const auto c = v.probe_coord(p);
    const std::array<int32_t, 3> ijk{int32_t(c[0]), int32_t(c[1]), int32_t(c[2])};
    for (vdb::Grid* g : {&irradiance, &offset, &state}) g->coords.push_back(ijk);
    irradiance.values.insert(irradiance.values.end(), {l0 * v.sh(p, 0, 0), l0 * v.sh(p, 0, 1), l0 * v.sh(p, 0, 2)});
    const loader::Vec3 o = v.offset(p);
    offset.values.insert(offset.values.end(), {o[0], o[1], o[2]});
    state.values.push_back(v.state(p) == GIBAKE_PROBE_INACTIVE ? 1.f : 0.f);
  }
  irradiance.meta.push_back(vdb::Meta::string("units", "lux"));
  offset.meta.push_back(vdb::Meta::string("units", "m"));
  state.meta.push_back(vdb::Meta::string("meaning", "0 active, 1 inactive"));
  for (vdb::Grid* g : {&irradiance, &offset, &state}) grids.push_back(std::move(*g));
}

// LPV cascade k as grids named like bake/lpv/lpv.h lpv_dense_grids(): lpv<k>_<c>_sh0 (float, band 0,
// cd) and lpv<k>_<c>_sh1 (vec3 (c3, c1, c2): band 1 as a vector), index space = cell coordinates.
// Zero values stay inactive.
void add_lpv_grids(const loader::LpvCascade& c, std::vector<vdb::Grid>& grids) {
  const gibake_lpv_cascade& d = c.desc();
  const vdb::Transform xform = cell_transform(d.cell_size, d.grid_min);
  static const char* const kChannel[3] = {"r", "g", "b"};
  for (uint32_t ch = 0; ch < 3; ++ch) {
    const std::string prefix = "lpv" + std::to_string(d.cascade_index) + "_" + kChannel[ch];
    vdb::Grid sh0 = grid(prefix + "_sh0", 1, xform), sh1 = grid(prefix + "_sh1", 3, xform);
    for (int32_t z = 0; z < d.dims[2]; ++z)
      for (int32_t y = 0; y < d.dims[1]; ++y)
        for (int32_t x = 0; x < d.dims[0]; ++x) {
          const uint32_t i = c.cell_index(x, y, z);
          const float v0 = c.sh(i, ch, 0);
          const float v1[3] = {c.sh(i, ch, 3), c.sh(i, ch, 1), c.sh(i, ch, 2)};
          if (v0 != 0.f) {
            sh0.coords.push_back({x, y, z});
            sh0.values.push_back(v0);
          }
          if (v1[0] != 0.f || v1[1] != 0.f || v1[2] != 0.f) {
            sh1.coords.push_back({x, y, z});
            sh1.values.insert(sh1.values.end(), v1, v1 + 3);
          }
        }
    for (vdb::Grid* g : {&sh0, &sh1}) {
      g->meta.push_back(vdb::Meta::string("units", "cd (L1 SH of radiant intensity, direction of travel)"));
      grids.push_back(std::move(*g));
    }
  }
}

// Voxel-GI volume k, level 0 (format 1.3): vxgi<k>_<face> (Vec3SGrid, face px nx py ny pz nz) holds
// the radiance (cd/m^2, un-premultiplied) leaving each voxel through that face, vxgi<k>_alpha
// (FloatGrid) the largest alpha over the faces; index space = voxel coordinates, voxel centres on
// the bake's voxel centres.
void add_vxgi_grids(const loader::VxgiVolume& v, std::vector<vdb::Grid>& grids) {
  const gibake_vxgi_volume& d = v.desc();
  const vdb::Transform xform = cell_transform(d.voxel_size, d.grid_min);
  static const char* const kFace[6] = {"px", "nx", "py", "ny", "pz", "nz"};
  const std::string prefix = "vxgi" + std::to_string(d.clipmap_index) + "_";
  const size_t X = size_t(d.dims[0]), Y = size_t(d.dims[1]);
  std::vector<float> alpha(X * Y * size_t(d.dims[2]), 0.f);
  for (uint32_t f = 0; f < 6; ++f) {
    vdb::Grid g = grid(prefix + kFace[f], 3, xform);
    for (int32_t z = 0; z < d.dims[2]; ++z)
      for (int32_t y = 0; y < d.dims[1]; ++y)
        for (int32_t x = 0; x < d.dims[0]; ++x) {
          const loader::Rgba t = v.texel(0, f, x, y, z);
          if (!(t[3] > 0.f)) continue;
          g.coords.push_back({x, y, z});
          g.values.insert(g.values.end(), {t[0] / t[3], t[1] / t[3], t[2] / t[3]});
          float& a = alpha[size_t(x) + X * (size_t(y) + Y * size_t(z))];
          a = std::max(a, t[3]);
        }
    g.meta.push_back(vdb::Meta::string("units", "cd/m^2 (radiance leaving the voxel through this face)"));
    grids.push_back(std::move(g));
  }
  vdb::Grid a = grid(prefix + "alpha", 1, xform);
  for (int32_t z = 0; z < d.dims[2]; ++z)
    for (int32_t y = 0; y < d.dims[1]; ++y)
      for (int32_t x = 0; x < d.dims[0]; ++x) {
        const float value = alpha[size_t(x) + X * (size_t(y) + Y * size_t(z))];
        if (!(value > 0.f)) continue;
        a.coords.push_back({x, y, z});
        a.values.push_back(value);
      }
  grids.push_back(std::move(a));
}

}  // namespace

Status export_vdb(const loader::BakeFile& file, const std::string& path) {
  if (file.ddgi_volumes().empty() && file.lpv_cascades().empty() && file.vxgi_volumes().empty())
    return Status::invalid("", "export", "the bake file has no DDGI volume, LPV cascade or voxel GI volume");
  vdb::File vdb;
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i)
    add_volume_grids(file.ddgi_volumes()[i], i == 0 ? "" : "_" + std::to_string(i), vdb.grids);
  for (const loader::LpvCascade& c : file.lpv_cascades()) add_lpv_grids(c, vdb.grids);
  for (const loader::VxgiVolume& v : file.vxgi_volumes()) add_vxgi_grids(v, vdb.grids);
  AtomicFile out;
  GIBAKE_TRY(out.begin(path));
  GIBAKE_TRY(vdb::write_file(out.temp_path(), vdb, path));
  return out.commit();
}

}  // namespace gibake
