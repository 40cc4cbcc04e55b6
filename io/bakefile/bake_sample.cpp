#include "io/bakefile/bake_sample.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace gibake {
namespace {

// Strict float: the whole field, finite.
bool parse_float(const std::string& field, float& out) {
  size_t b = field.find_first_not_of(" \t\r"), e = field.find_last_not_of(" \t\r");
  if (b == std::string::npos) return false;
  const std::string f = field.substr(b, e - b + 1);
  char* end = nullptr;
  const double v = std::strtod(f.c_str(), &end);
  if (end != f.c_str() + f.size() || !std::isfinite(v) || std::fabs(v) > 3.0e38) return false;
  out = float(v);
  return true;
}

std::string num(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  return buf;
}

}  // namespace

Status parse_sample_points(const std::string& file, const std::string& text, std::vector<SamplePoint>& out) {
  out.clear();
  // A UTF-8 byte-order mark (some editors write one) is no part of the first field.
  std::istringstream in(text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? text.substr(3) : text);
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    const std::string where = "line " + std::to_string(number);
    if (fields.size() != 6) return Status::invalid(file, where, "expected 6 numbers x,y,z,nx,ny,nz, found " + std::to_string(fields.size()) + " fields");
    SamplePoint sp;
    float v[6];
    for (int k = 0; k < 6; ++k)
      if (!parse_float(fields[size_t(k)], v[k]))
        return Status::invalid(file, where, "field " + std::to_string(k + 1) + " is not a finite number");
    // In double: any non-zero float normal, however short or long, has a length there.
    const double len = std::sqrt(double(v[3]) * v[3] + double(v[4]) * v[4] + double(v[5]) * v[5]);
    if (!(len > 0.0)) return Status::invalid(file, where, "the normal has zero length");
    for (int a = 0; a < 3; ++a) {
      sp.p[size_t(a)] = v[a];
      sp.n[size_t(a)] = float(double(v[3 + a]) / len);
    }
    out.push_back(sp);
  }
  return Status::ok();
}

Status sample_points(const loader::BakeFile& file, SampleSource source, std::vector<SamplePoint>& points) {
  auto none = [](const std::string& what) { return Status::error(ExitCode::BadArguments, "", "--source", what); };
  if (source == SampleSource::Ddgi && file.ddgi_volumes().empty()) return none("the bake file has no DDGI volume");
  if (source == SampleSource::Lpv && file.lpv_cascades().empty()) return none("the bake file has no LPV cascade");
  if (source == SampleSource::Vxgi && file.vxgi_volumes().empty()) return none("the bake file has no voxel GI volume");
  for (SamplePoint& sp : points) {
    sp.rgb.reset();
    if (source == SampleSource::Ddgi) {
      loader::Rgb e;
      if (file.sample_ddgi(sp.p, sp.n, e)) sp.rgb = e;  // every volume blended; none outside them all
    } else if (source == SampleSource::Lpv) {
      for (const loader::LpvCascade& c : file.lpv_cascades())
        if (c.contains(sp.p)) {
          sp.rgb = c.sample_irradiance(sp.p, sp.n);
          break;
        }
    } else {
      loader::Rgb e;
      if (file.sample_vxgi(sp.p, sp.n, e)) sp.rgb = e;
    }
  }
  return Status::ok();
}

void write_sample_points(const std::vector<SamplePoint>& points, bool json, std::ostream& out) {
  for (const SamplePoint& sp : points) {
    if (json) {
      out << "{\"x\":" << num(sp.p[0]) << ",\"y\":" << num(sp.p[1]) << ",\"z\":" << num(sp.p[2])
          << ",\"nx\":" << num(sp.n[0]) << ",\"ny\":" << num(sp.n[1]) << ",\"nz\":" << num(sp.n[2]);
      for (int c = 0; c < 3; ++c)
        out << ",\"" << "rgb"[c] << "\":" << (sp.rgb ? num((*sp.rgb)[size_t(c)]) : std::string("null"));
      out << "}\n";
    } else {
      out << num(sp.p[0]) << ',' << num(sp.p[1]) << ',' << num(sp.p[2]) << ',' << num(sp.n[0]) << ','
          << num(sp.n[1]) << ',' << num(sp.n[2]);
      for (int c = 0; c < 3; ++c) out << ',' << (sp.rgb ? num((*sp.rgb)[size_t(c)]) : std::string());
      out << '\n';
    }
  }
}

}  // namespace gibake
