// gibake sample bake.gibake --points pts.csv --source ddgi|lpv|vxgi [--format csv|json]: the
// irradiance (lux) the loader's sampler for that source returns at each point (io/bakefile/bake_sample.h).
// With --source vxgi --backend vulkan the diffuse cone trace runs in the GLSL include on a device
// (bake/pipeline/vxgi_sample.h); --timing prints the query time to stderr (bench/vxgi_bench.sh).
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "bake/pipeline/vxgi_sample.h"
#include "cli/commands.h"
#include "cli/help.h"
#include "cli/options.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_sample.h"
#include "io/bakefile/bake_verify.h"
#include "io/timer.h"

namespace gibake::cli {
namespace {

struct SampleArgs {
  std::string path, points, source, format = "csv";
  std::string backend = "cpu", vulkan_device;
  bool timing = false;
};

// The vxgi diffuse cone trace of every point inside a clipmap on a Vulkan device.
Status sample_on_device(const SampleArgs& c, const loader::BakeFile& file, std::vector<SamplePoint>& points) {
  if (file.vxgi_volumes().empty())
    return Status::error(ExitCode::BadArguments, "", "--source", "the bake file has no voxel GI volume");
  BackendSettings settings;
  GIBAKE_TRY(parse_backend_options(c.backend, c.vulkan_device, settings));
  DeviceSampleReport report;
  GIBAKE_TRY(sample_vxgi_vulkan(settings, file, points, report));
  if (c.timing && report.queries)
    std::fprintf(stderr, "gibake: sample: %zu vxgi queries on %s in %.4f s (uploads and readback included)\n",
                 report.queries, report.device.c_str(), report.seconds);
  else if (c.timing)
    std::fprintf(stderr, "gibake: sample: 0 vxgi queries (no point inside a clipmap), nothing run on the device\n");
  return Status::ok();
}

void sample_options(CLI::App& sub, SampleArgs& a) {
  sub.description("Print a bake's irradiance (lux) at points, as an engine's sampler reads it");
  sub.footer("Prints x,y,z,nx,ny,nz,r,g,b a point; a point outside every volume gets empty r,g,b.\n"
             "Every option at length: docs/cli/sample.md");
  sub.add_option("FILE", a.path, "the bake file")->required()->group("Input and output");
  OptionGroup g(sub, "Input and output"), r(sub, "How it runs");
  g.option("--points", a.points, "FILE", "CSV file: x,y,z,nx,ny,nz a line ('#' comments)")->required();
  g.option("--source", a.source, "ddgi|lpv|vxgi", "which of the bake's volumes to sample")
      ->required()
      ->check(CLI::IsMember({"ddgi", "lpv", "vxgi"}));
  g.option("--format", a.format, "csv|json", "output format on stdout")
      ->check(CLI::IsMember({"csv", "json"}))
      ->capture_default_str();
  r.option("--backend", a.backend, "cpu|vulkan", "where the queries run (vulkan: --source vxgi only)")
      ->check(CLI::IsMember({"cpu", "vulkan"}))
      ->capture_default_str();
  r.option("--vulkan-device", a.vulkan_device, "D", "an index or name, or lavapipe (with --backend vulkan)");
  r.flag("--timing", a.timing, "print the query time to stderr");
}

int run_sample(const SampleArgs& c) {
  // A folder opens as a stream that reads nothing: it would pass for a file of no points.
  struct stat info {};
  if (::stat(c.points.c_str(), &info) == 0 && S_ISDIR(info.st_mode))
    return report_error(Status::error(ExitCode::IoFailure, c.points, "--points", "is a folder, not a file"));
  // A device (/dev/zero, a disk) never ends; a file or a pipe (`--points <(...)`) does.
  if (::stat(c.points.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISFIFO(info.st_mode))
    return report_error(Status::error(ExitCode::IoFailure, c.points, "--points", "is not a regular file or a pipe"));
  std::ifstream in(c.points, std::ios::binary);
  if (!in) return report_error(Status::io(c.points, "cannot open the points file"));
  std::stringstream text;
  text << in.rdbuf();
  std::vector<SamplePoint> points;
  if (Status st = parse_sample_points(c.points, text.str(), points); !st) return report_error(st);
  loader::BakeFile file;
  if (Status st = open_bake_file(c.path, file, /*verify_checksums=*/true, /*probe_major_tiles=*/true); !st)
    return report_error(st);
  if (Status st = check_values_readable(file, c.path); !st) return report_error(st);
  const SampleSource source = c.source == "ddgi" ? SampleSource::Ddgi
                              : c.source == "lpv" ? SampleSource::Lpv : SampleSource::Vxgi;
  if (c.backend == "cpu" && !c.vulkan_device.empty())
    return report_error(bad_arg("--vulkan-device", "names a device for --backend vulkan"));
  if (c.backend != "cpu" && source != SampleSource::Vxgi)
    return report_error(bad_arg("--backend", "only --source vxgi runs on a Vulkan device"));
  const auto t0 = Clock::now();
  const Status st = c.backend == "cpu" ? sample_points(file, source, points) : sample_on_device(c, file, points);
  if (!st) return report_error(Status::error(st.code(), c.path, st.where(), st.what()));
  if (c.timing && c.backend == "cpu")
    std::fprintf(stderr, "gibake: sample: %zu %s queries on the CPU (one thread) in %.4f s\n", points.size(),
                 c.source.c_str(), seconds_since(t0));
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
