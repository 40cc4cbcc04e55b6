// gibake merge part_*.gibake --out probes.gibake [--threads N] [--progress MODE]
//                                                [--backend B --vulkan-device D]
// Finishes a bake split with `gibake bake --shard I/N` (bake/ddgi/shard_merge.h).
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "bake/ddgi/shard_merge.h"
#include "cli/bake_args.h"
#include "cli/bake_summary.h"
#include "cli/commands.h"
#include "cli/progress.h"
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
  sub.description("Merge the shard files of a bake split with 'gibake bake --shard I/N' into one bake file");
  sub.add_option("parts", a.parts, "shard files (any order, every shard once)")->required();
  sub.add_option("--out,-o", a.out, "merged bake file (byte-identical to the bake made without --shard)");
  sub.add_option("--threads", a.threads, "worker threads (0 = all; results do not depend on it)")
      ->check(CLI::Range(0u, kMaxThreads));
  sub.add_option("--progress", a.progress, "auto|bar|lines|json (stderr)");
  sub.add_option("--backend", a.backend,
                 "only for a --gather probes bake made on Vulkan: where its bounce passes run (default: the "
                 "device its settings name)");
  sub.add_option("--vulkan-device", a.vulkan_device, "index, name or lavapipe (with --backend vulkan)");
}

int run_merge(const MergeArgs& a) {
  const auto t0 = Clock::now();
  MergeOptions options;
  options.parts = a.parts;
  options.out = a.out;
  if (a.out.empty()) return report_error(bad_arg("--out", "an output file is required (--out probes.gibake)"));
  ProgressMode mode;
  if (!parse_progress_mode(a.progress, mode)) return report_error(bad_arg("--progress", "expected auto, bar, lines or json"));
  if (!parse_backend(a.backend, options.backend.backend))
    return report_error(bad_arg("--backend", "expected auto, cpu or vulkan"));
  options.backend.vulkan_device = a.vulkan_device;
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
