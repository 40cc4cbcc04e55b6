// Sanity figure: LPV irradiance against the DDGI bake at the DDGI probe positions.
//   lpv_vs_ddgi FILE.gibake     (a bake with both --ddgi and --lpv)
// For every active probe inside an LPV cascade and the 6 axis normals: DDGI E(n) from the probe's
// own SH, LPV E(n) from BakeFile::sample_lpv, both in lux, as (R+G+B)/3. Prints the Pearson
// correlation, the ratio of the means (LPV/DDGI) and the median per-sample ratio.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "gibake/loader.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: lpv_vs_ddgi FILE.gibake\n");
    return 1;
  }
  gibake::loader::BakeFile file;
  if (gibake::loader::Error e = file.open(argv[1])) {
    std::fprintf(stderr, "%s: %s\n", argv[1], e.message.c_str());
    return 3;
  }
  if (file.ddgi_volumes().empty() || file.lpv_cascades().empty()) {
    std::fprintf(stderr, "%s: needs a DDGI volume and LPV cascades\n", argv[1]);
    return 1;
  }
  const gibake::loader::DdgiVolume& v = file.ddgi_volumes()[0];
  static const gibake::loader::Vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<double> ddgi, lpv;
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    if (v.state(p) == GIBAKE_PROBE_INACTIVE) continue;
    const gibake::loader::Vec3 pos = v.probe_position(p);
    bool inside = false;
    for (const auto& c : file.lpv_cascades()) inside = inside || c.contains(pos);
    if (!inside) continue;
    for (const auto& n : kAxes) {
      const gibake::loader::Rgb d = v.sh_irradiance(p, n), l = file.sample_lpv(pos, n);
      ddgi.push_back((double(d[0]) + d[1] + d[2]) / 3.0);
      lpv.push_back((double(l[0]) + l[1] + l[2]) / 3.0);
    }
  }
  const size_t n = ddgi.size();
  if (n < 2) {
    std::fprintf(stderr, "no active probe inside the LPV\n");
    return 1;
  }
  double ma = 0, mb = 0;
  for (size_t i = 0; i < n; ++i) ma += ddgi[i], mb += lpv[i];
  ma /= double(n), mb /= double(n);
  double sab = 0, saa = 0, sbb = 0;
  std::vector<double> ratios;
  for (size_t i = 0; i < n; ++i) {
    sab += (ddgi[i] - ma) * (lpv[i] - mb);
    saa += (ddgi[i] - ma) * (ddgi[i] - ma);
    sbb += (lpv[i] - mb) * (lpv[i] - mb);
    if (ddgi[i] > 1e-6 * ma) ratios.push_back(lpv[i] / ddgi[i]);
  }
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios.empty() ? 0.0 : ratios[ratios.size() / 2];
  std::printf("samples %zu (probes x 6 normals)  mean DDGI %.4g lux  mean LPV %.4g lux\n", n, ma, mb);
  std::printf("pearson %.3f  ratio of means (LPV/DDGI) %.3f  median ratio %.3f\n", sab / std::sqrt(saa * sbb),
              mb / ma, median);
  return 0;
}
