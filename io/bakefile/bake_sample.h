// `gibake sample`: the irradiance the loader's samplers return at chosen points (README, "Querying
// a bake at points"). Points: one `x,y,z,nx,ny,nz` per line (metres, normal of any length > 0,
// normalised here; blank lines and `#` comments allowed).
#pragma once
#include <array>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/status.h"

namespace gibake {

enum class SampleSource { Ddgi, Lpv, Vxgi };

struct SamplePoint {
  std::array<float, 3> p{}, n{};
  std::optional<std::array<float, 3>> rgb;  // lux; empty when no volume of the source contains p
};

// Parses the points file's text; InvalidInput "<file>: line N: <what>" on the first bad line.
Status parse_sample_points(const std::string& file, const std::string& text, std::vector<SamplePoint>& out);

// Samples every point: DDGI blended over every volume whose region (probe cells, [grid_min -
// spacing/2, grid_max + spacing/2]) holds p (BakeFile::sample_ddgi, docs/FORMAT.md "Several
// volumes"), LPV from the finest cascade containing p, VXGI the diffuse cone trace of
// the finest clipmap containing p. BadArguments when the file has no data of that source.
Status sample_points(const loader::BakeFile& file, SampleSource source, std::vector<SamplePoint>& points);

// `x,y,z,nx,ny,nz,r,g,b` lines (empty r,g,b outside) or one JSON object per line (null outside).
void write_sample_points(const std::vector<SamplePoint>& points, bool json, std::ostream& out);

}  // namespace gibake
