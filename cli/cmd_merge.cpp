// gibake merge part_*.gibake --out probes.gibake [--threads N] [--progress MODE]
//                                                [--backend B --vulkan-device D]
// Finishes a bake split with `gibake bake --shard I/N` (bake/ddgi/shard_merge.h).
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "bake/ddgi/shard_merge.h"
#include "bake/pipeline/devices.h"
#include "cli/bake_args.h"
#include "cli/bake_summary.h"
#include "cli/commands.h"
#include "cli/help.h"
#include "cli/progress.h"
#include "io/output/output_check.h"
#include "io/timer.h"

namespace gibake::cli {
namespace {

struct MergeArgs {
  std::vector<std::string> parts;
  std::string out;
  unsigned threads = 0;
  std::string progress = "auto";
  std::string backend = "auto";
  std::string vulkan_device;
};

void merge_options(CLI::App& sub, MergeArgs& a) {
  sub.description("Merge the shard files of a bake split with 'gibake bake --shard I/N'");
  sub.footer(
      "Writes the bake file the same bake without --shard writes, byte for byte.\n"
      "Shards of a bake that fits its atlases (the default) finish with its own --from-shards.\n"
      "Every option at length: docs/cli/merge.md");
  const std::string io = "Input and output", run = "How it runs";
  sub.add_option("PART", a.parts, "the shard files, in any order, every shard once")->required()->group(io);
  OptionGroup g(sub, io), r(sub, run);
  g.option("--out,-o", a.out, "FILE", "the merged bake file");
  add_threads_option(&sub, a.threads, "results", run);
  r.option("--progress", a.progress, "MODE", "progress on stderr: auto, bar, lines or json")->capture_default_str();
  r.option("--backend", a.backend, "auto|cpu|vulkan", "where a Vulkan --gather probes bake's bounces run")
      ->capture_default_str();
  r.option("--vulkan-device", a.vulkan_device, "D", "an index or name, or lavapipe (with --backend vulkan or auto)");
}

int run_merge(const MergeArgs& a) {
  const auto t0 = Clock::now();
  MergeOptions options;
  options.parts = a.parts;
  options.out = a.out;
  if (a.out.empty()) return report_error(bad_arg("--out", "an output file is required (--out probes.gibake)"));
  if (Status st = check_bake_file_name("--out", a.out); !st) return report_error(st);
  // Before the parts are read and merged: an output that cannot be written, or that is a part.
  std::vector<NamedPath> parts;
  for (const std::string& part : a.parts) parts.push_back({"PART", part});
  if (Status st = check_output_paths({{"--out", a.out}}, parts); !st) return report_error(st);
  ProgressMode mode;
  if (Status st = parse_progress_option(a.progress, mode); !st) return report_error(st);
  if (Status st = parse_backend_options(a.backend, a.vulkan_device, options.backend); !st) return report_error(st);
  const PipelineDevices platform;
  options.platform = &platform;
  auto progress = std::make_shared<Progress>(mode);
  Context ctx = progress_context(progress, a.threads);
  MergeReport report;
  const Status st = merge_shard_files(options, ctx, report);
  progress->clear();
  if (!st) return report_error(st);
  report.stage_seconds.emplace_back("total", seconds_since(t0));
  std::fprintf(stderr, "gibake: merged %u shard(s)%s%s\n", report.shards,
               report.volumes > 1 ? (" of " + std::to_string(report.volumes) + " probe volumes").c_str() : "",
               report.lpv ? ", LPV cascades from shard 0" : "");
  BakeSummary summary;
  summary.out = a.out;
  summary.result = &report.result;
  summary.report = &report.ddgi;
  summary.timings = report.stage_seconds;
  print_bake_summary(summary, progress->mode());
  return 0;
}

}  // namespace

const Command kMergeCommand{"merge", add_command<MergeArgs, merge_options, run_merge>};

}  // namespace gibake::cli
