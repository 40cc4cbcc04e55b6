// gibake sample bake.gibake --points pts.csv --source ddgi|lpv|vxgi [--format csv|json]: the
// irradiance (lux) the loader's sampler for that source returns at each point (io/bakefile/bake_sample.h).
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "cli/commands.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_sample.h"

namespace gibake::cli {
namespace {

struct SampleArgs {
  std::string path, points, source, format = "csv";
};

void sample_options(CLI::App& sub, SampleArgs& a) {
  sub.description("Irradiance (lux) of a bake at points, as an engine's sampler sees it");
  sub.add_option("file", a.path, "Bake file")->required();
  sub.add_option("--points", a.points, "CSV file: x,y,z,nx,ny,nz per line ('#' comments)")->required();
  sub.add_option("--source", a.source, "ddgi|lpv|vxgi")->required()->check(CLI::IsMember({"ddgi", "lpv", "vxgi"}));
  sub.add_option("--format", a.format, "csv|json (default csv)")->check(CLI::IsMember({"csv", "json"}));
}

int run_sample(const SampleArgs& c) {
  std::ifstream in(c.points, std::ios::binary);
  if (!in) return report_error(Status::io(c.points, "cannot open the points file"));
  std::stringstream text;
  text << in.rdbuf();
  std::vector<SamplePoint> points;
  if (Status st = parse_sample_points(c.points, text.str(), points); !st) return report_error(st);
  loader::BakeFile file;
  if (Status st = open_bake_file(c.path, file); !st) return report_error(st);
  const SampleSource source = c.source == "ddgi" ? SampleSource::Ddgi
                              : c.source == "lpv" ? SampleSource::Lpv : SampleSource::Vxgi;
  if (Status st = sample_points(file, source, points); !st)
    return report_error(Status::error(st.code(), c.path, st.where(), st.what()));
  size_t outside = 0;
  for (const SamplePoint& sp : points) outside += sp.rgb ? 0 : 1;
  std::ostringstream out;  // all or nothing: written once every point is sampled
  write_sample_points(points, c.format == "json", out);
  std::cout << out.str() << std::flush;
  if (outside)
    print_warning(c.points + ": " + std::to_string(outside) + " of " + std::to_string(points.size()) +
                  " points lie outside every " + c.source + " volume (empty values)");
  return 0;
}

}  // namespace

const Command kSampleCommand{"sample", add_command<SampleArgs, sample_options, run_sample>};

}  // namespace gibake::cli
