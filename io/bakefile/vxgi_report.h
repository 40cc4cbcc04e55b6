// The voxel-GI part of `gibake info` and `gibake verify` (format 1.3), beside the DDGI and LPV parts.
#pragma once
#include <nlohmann/json.hpp>
#include <ostream>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_verify.h"

namespace gibake {

nlohmann::json vxgi_info_json(const loader::VxgiVolume& v);
void print_vxgi_info(const nlohmann::json& volumes, std::ostream& out);
// finite (vxgi[k].finite), and per volume vxgi[k].range: alpha within [0, 1] and rgb >= 0 (up to
// float16 rounding, 1e-3).
void verify_vxgi(const loader::BakeFile& file, VerifyReport& report);
// against.vxgi.structure, then against.vxgi[k].radiance: every texel of every level and face, RGBA,
// judged by |a - ref| <= T max(1, |ref|).
void compare_vxgi(const loader::BakeFile& a, const loader::BakeFile& b, double tolerance, VerifyReport& report);

}  // namespace gibake
