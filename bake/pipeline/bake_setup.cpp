#include "bake/pipeline/bake_setup.h"

#include <tbb/task_group.h>

#include <chrono>

#include "bake/voxel/enclosure.h"
#include "bake/vulkan/pipelines.h"
#include "bake/vulkan/session.h"
#include "io/timer.h"

namespace gibake {

Status build_bake_setup(const Scene& scene, const SetupSettings& s, VulkanWarmup* warmup, const BakeSetupParts& parts,
                        const Context& ctx, tbb::task_arena& arena, BakeSetup& out) {
  const auto t_all = Clock::now();
  out = BakeSetup{};
  double prepare_s = 0.0, voxels_s = 0.0, mips_s = 0.0, gpu_s = 0.0;
  Status prepared = Status::ok(), voxelized = Status::ok(), gpu_built = Status::ok(), textures_made = Status::ok(),
         uploaded = Status::ok();
  // The backend is chosen once the set-up's first tasks run (the driver lists the devices while the
  // scene imports, and may still be at it), and the device is taken only once the host's share of
  // its set-up (BVH build, texture packing) is under way: the driver goes on opening it meanwhile.
  if (parts.gpu) {
    out.gpu = std::make_shared<GpuSession>();
    if (s.backend.backend != Backend::Cpu) GIBAKE_TRY(open_bvh_builder(*out.gpu));
  }
  bool gpu_scene = false;
  Status chosen = Status::ok(), opened = Status::ok();
  PackedTextures packed;
  if (parts.bvh) {
    PrepareOptions options;
    options.blend_cutoff = s.blend_cutoff;
    const auto t0 = Clock::now();
    GIBAKE_TRY(PreparedScene::create_unbuilt(scene, out.prepared, options));
    prepare_s = seconds_since(t0);
  }
  arena.execute([&] {
    tbb::task_group group;
    if (parts.bvh)
      group.run([&] {
        const auto t0 = Clock::now();
        prepared = out.prepared->build();
        prepare_s += seconds_since(t0);
      });
    if (parts.enclosure)
      group.run([&] {
        const auto t0 = Clock::now();
        voxelized = make_enclosure_voxels(scene, s, ctx, out.voxels, &arena);
        voxels_s = seconds_since(t0);
      });
    if (parts.gpu) {
      chosen = choose_gpu_backend(s.backend, *out.gpu, warmup);
      gpu_scene = chosen && out.gpu->choice.backend == Backend::Vulkan;
    }
    if (gpu_scene)
      group.run([&] {
        const auto t0 = Clock::now();
        gpu_built = build_gpu_session_bvh(scene, s.blend_cutoff, ctx, &arena, *out.gpu);
        gpu_s = seconds_since(t0);
      });
    if (parts.mips) {
      const auto t0 = Clock::now();
      out.lod = TextureLod(scene, ctx, &arena);
      mips_s = seconds_since(t0);
      if (gpu_scene) pack_gpu_textures(scene, out.lod, packed);
    }
    // The path kernel's textures go up while the BVH is still being built, and beside its upload.
    tbb::task_group textures;
    if (gpu_scene) {
      opened = take_gpu_device(s.backend, *out.gpu, warmup);
      // The driver makes the bake's pipelines on a thread of its own beside the uploads (several ms
      // each, on the way of the BVH upload, relocation and the trace's set-up otherwise).
      if (opened && out.gpu->vk) pipelines::create_ddgi_pipelines_beside(*out.gpu->vk, parts.probe_field_kernels);
      if (opened && out.gpu->vk && parts.mips)
        textures.run(
            [&] { textures_made = upload_gpu_texture_pool(*out.gpu->vk, std::move(packed), out.gpu->textures); });
    }
    group.wait();
    if (gpu_scene && opened && out.gpu->vk && gpu_built) {
      const auto t0 = Clock::now();
      uploaded = upload_gpu_session_scene(ctx, *out.gpu);
      gpu_s += seconds_since(t0);
    }
    textures.wait();
  });
  GIBAKE_TRY(chosen);
  GIBAKE_TRY(opened);
  GIBAKE_TRY(prepared);
  GIBAKE_TRY(voxelized);
  GIBAKE_TRY(gpu_built);
  GIBAKE_TRY(textures_made);
  GIBAKE_TRY(uploaded);
  if (out.gpu && out.gpu->choice.automatic) ctx.note(auto_decision_text(out.gpu->choice.decision));
  if (gpu_scene && !out.gpu->vk) out.gpu->scene = GpuSceneData{};  // auto's device did not open: the CPU bakes
  if (parts.bvh) {
    ctx.report("prepare", 1, 1);
    out.stage_seconds.emplace_back("prepare", prepare_s);
  }
  if (!out.voxels.empty()) out.stage_seconds.emplace_back("voxelize (enclosure)", voxels_s);
  if (parts.mips) out.stage_seconds.emplace_back("texture mips", mips_s);
  if (gpu_scene && out.gpu->vk) out.stage_seconds.emplace_back("vulkan (BVH, upload)", gpu_s);
  if (out.gpu && out.gpu->textures)
    out.stage_seconds.emplace_back("vulkan textures (packed, uploaded)",
                                   out.gpu->textures->pack_seconds + out.gpu->textures->upload_seconds);
  out.stage_seconds.emplace_back("set-up (side by side)", seconds_since(t_all));
  return Status::ok();
}

}  // namespace gibake
