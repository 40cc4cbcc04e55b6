#include "bake/pipeline/check_refine.h"

#include <cmath>

#include "bake/ddgi/volume_plan.h"
#include "bake/pipeline/devices.h"
#include "io/timer.h"

namespace gibake {

Status encode_baked_volumes(const BakeRequest& r, const BakeResult& run, std::vector<uint8_t>& bytes) {
  BakeOutputs outputs;
  outputs.ddgi = &run.volumes[0].result;
  for (size_t i = 1; i < run.volumes.size(); ++i) outputs.ddgi_more.push_back(&run.volumes[i].result);
  outputs.metadata_json = "{}";
  BakeFileOptions options = r.file_options;
  options.threads = r.threads;
  options.warn = nullptr;  // the file's own write reports what it clamps
  options.timing = nullptr;
  options.stream = nullptr;
  options.dense_volumes = true;  // the surface fit maps the file's atlas texels back onto the results'
  return build_bake_file(outputs, options, bytes);
}

namespace {

// The pass's check: this many times the file's check's patches (--check-patches; bricks need more
// of them than a figure does), with its paths a point (--check-rays).
constexpr uint32_t kPassPatches = 16;

// Patches from the check views when the bake has them (what the user looks at), else from the
// probes' view.
ReconstructionSettings pass_settings(const BakeRequest& r, const BakeResult& run) {
  ReconstructionSettings rs;
  rs.patches = kPassPatches * r.check.patches;
  rs.rays = r.check.rays;
  // The check's second pass too: a patch is judged beyond its reference's noise, and a noisy one
  // can say nothing (docs/BENCHMARKS.md "The check's second pass").
  rs.target_noise = r.check.target_noise;
  rs.ray_budget = r.check.ray_budget;
  // Other patches than the file's own check (seeded by the bake's seed), so that the check after
  // the pass does not measure the very points the pass refined for.
  rs.seed = r.ddgi_settings.seed ^ 0x5eedc4ec4f1e5ull;
  rs.cameras = run.check_cameras;
  rs.width = r.check.width;
  rs.height = r.check.height;
  return rs;
}

// The check on the baked volumes: its reference (on the bake's device when it has one) and ratios.
Status check_volumes(const BakeRequest& r, const Context& ctx, BakeResult& run, const ReconstructionSettings& rs,
                     ReconstructionReference& reference, ReconstructionError& error) {
  std::vector<uint8_t> bytes;
  GIBAKE_TRY(encode_baked_volumes(r, run, bytes));
  loader::BakeFile file;
  if (loader::Error e = file.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{false}))
    return Status::error(ExitCode::RuntimeFailure, r.files.out, loader::error_code_name(e.code), e.message);
  std::vector<const DdgiResult*> volumes;
  for (const BakedVolume& v : run.volumes) volumes.push_back(&v.result);
  std::unique_ptr<ReferencePathDevice> device = make_reference_path_device(run.gpu);
  ReconstructionSettings traced = rs;
  traced.device = device.get();
  GIBAKE_TRY(trace_bake_reconstruction_reference(*run.prepared, run.lod, run.volumes[0].result.settings_json,
                                                 active_probe_positions(volumes), traced, ctx, reference));
  return finish_bake_reconstruction(*run.prepared, run.lod, file, reference, rs, ctx, error);
}

}  // namespace

std::vector<CheckMiss> check_misses(const ReconstructionReference& reference, const ReconstructionError& error,
                                    const ReconstructionSettings& s) {
  // error.samples are the reference's patches that met a surface, in patch order.
  std::vector<size_t> index;
  for (size_t i = 0; i < reference.patches.size(); ++i)
    if (reference.patches[i].points > 0) index.push_back(i);
  std::vector<CheckMiss> misses;
  if (index.size() != error.samples.size() || error.samples.empty()) return misses;
  double mean = 0.0;
  for (const ReconstructionPatch& p : error.samples) mean += p.reference / float(p.points);
  mean /= double(error.samples.size());
  for (size_t k = 0; k < index.size(); ++k) {
    const ReconstructionPatch& p = error.samples[k];
    if (!(p.reference / float(p.points) > s.floor_fraction * mean) || !(p.reference > 0.f)) continue;
    const double off = std::fabs(double(p.baked) / p.reference - 1.0);
    if (!(off > s.within + double(p.reference_stderr) / p.reference)) continue;
    for (const ReconstructionReference::Point& pt : reference.points[index[k]])
      misses.push_back(CheckMiss{{pt.p.x, pt.p.y, pt.p.z}, float(off)});
  }
  return misses;
}

Status refine_by_check(const BakeRequest& r, const Context& ctx, const RunContext& shared, BakeResult& run) {
  const VolumeSettings& vs = run.volume_settings;
  if (vs.check_budget == 0 || r.shard || run.volumes.empty() || !run.prepared) return Status::ok();
  if (run.volumes[0].kind != VolumeKind::Default) {
    const std::string none = "refinement by check: none (it refines the default grid, which --default-volume off leaves out)";
    ctx.note(none);
    run.refine_rule += (run.refine_rule.empty() ? "" : "; ") + none;
    return Status::ok();
  }
  const auto t0 = Clock::now();
  const ReconstructionSettings rs = pass_settings(r, run);
  ReconstructionReference reference;
  ReconstructionError error;
  GIBAKE_TRY(check_volumes(r, ctx, run, rs, reference, error));
  ctx.note("refinement by check, the baked volumes: " + reconstruction_summary(error));
  const std::vector<CheckMiss> misses = check_misses(reference, error, rs);
  std::vector<PlannedVolume> planned;
  std::string text;
  GIBAKE_TRY(plan_check_refined(run.scene, r.ddgi_settings, vs, run.volumes, misses, planned, text));
  ctx.note(text);
  run.refine_rule += (run.refine_rule.empty() ? "" : "; ") + text;
  run.timings.emplace_back("refinement by check (check, rule)", seconds_since(t0));
  RunContext ready = shared;
  ready.prepared = run.prepared.get();
  ready.texture_lod = &run.lod;
  ready.gpu_session = run.gpu.get();
  ready.voxels = run.voxels.empty() ? nullptr : &run.voxels;
  const size_t first = run.volumes.size();
  GIBAKE_TRY(bake_more_volumes(run.scene, r.ddgi_settings, planned, ready, ctx, run.volumes));
  for (size_t i = first; i < run.volumes.size(); ++i)
    for (const auto& [stage, sec] : run.volumes[i].report.stage_seconds)
      run.timings.emplace_back("volume " + std::to_string(i) + " " + stage, sec);
  return Status::ok();
}

}  // namespace gibake
