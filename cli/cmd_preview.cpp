// `gibake preview scene.gltf --bake probes.gibake --out view.png [options]`: argv -> PreviewSettings,
// then bake/preview/preview.h renders and writes. --reference renders the path-traced reference into --out;
// --diff FILE compares the lit view with the reference (false colour) and prints the relative RMS.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bake/preview/block_compare.h"
#include "bake/preview/explain.h"
#include "bake/preview/preview.h"
#include "bake/preview/reconstruction_check.h"
#include "cli/commands.h"
#include "cli/help.h"
#include "cli/options.h"
#include "cli/progress.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_match.h"
#include "io/bakefile/bake_verify.h"
#include "io/gltf/import.h"
#include "io/gltf/scene_inputs.h"
#include "io/output/bake_atomic.h"
#include "io/output/output_check.h"

namespace gibake::cli {
namespace {

constexpr int kDiffPixelGrid = 4;  // points a side of the lit view's pixel grid under --diff
// The block measure of --diff: 8x8-pixel blocks within 10% of the reference, blocks whose reference
// is darker than a thousandth of the mean block left out (black against black says nothing).
constexpr int kBlock = 8;
constexpr float kBlockWithin = 0.10f, kBlockFloor = 0.001f;
constexpr size_t kWorstBlocks = 5;  // listed for --explain

struct PreviewArgs {
  std::string scene, bake, out, diff;
  std::string reference_image;  // --reference-image: compare with this instead of rendering the reference
  std::string block_map;        // --block-map: where the 8x8 blocks of --diff fail, as a PNG
  std::string camera, size = "1280x720", mode = "lit", progress = "auto";
  float fov = 0.f;
  double exposure = std::nan("");
  bool reference = false;
  bool force = false;  // preview a bake that was not made from this scene
  int spp = 64;
  uint64_t seed = 0;
  unsigned threads = 0;
  size_t camera_index = 0;
  bool camera_index_given = false;  // --camera-index given: it must name one of the scene's cameras
  int32_t volume = -1;              // -1: every DDGI volume, blended
  std::vector<std::string> suns;
  std::string sky;
  float diff_floor = 0.01f;
  uint32_t check_patches = 0, check_rays = 128;      // --check-patches: the reconstruction check from this view
  float check_noise = 0.03f;                         // --check-noise
  uint32_t check_ray_budget = 0;                     // --check-ray-budget (0: the default)
  float normal_bias = -1.f, smooth_backface = -1.f;  // < 0: the loader's defaults
  float behind_fade = -1.f;                          // < 0: the loader's default
  std::string visibility = "on";
  std::string irradiance = "atlas";
  std::string explain;  // --explain X,Y
  uint32_t explain_paths = 4096;
};

// --fov, when given: an angle a camera can have. Unset (0 in PreviewSettings) is the glTF
// camera's, which a given 0 must not silently become.
CLI::Validator field_of_view() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::vector<double> v;
        if (!parse_numbers(text, ',', 1, v) || !(v[0] > 0.0 && v[0] < 179.0))
          return "field of view must be in (0, 179) degrees, got '" + text + "'";
        return {};
      },
      "DEG in (0, 179)");
}

void preview_options(CLI::App& sub, PreviewArgs& a) {
  sub.description("Render a view of a scene lit by its bake (PNG or EXR)");
  sub.footer("Renders SCENE from a camera, lit by the bake as an engine's sampler reads it, into --out.\n"
             "--reference renders the path-traced truth instead; --diff compares the two. docs/cli/preview.md");
  sub.add_option("SCENE", a.scene, "the scene: a .gltf or .glb file")->required()->group("Input and output");
  OptionGroup io(sub, "Input and output"), view(sub, "View"), ref(sub, "Reference and comparison"),
      sampler(sub, "Sampler (as an engine sets it)"), light(sub, "Lights"), run(sub, "How it runs");
  io.option("--bake,-b", a.bake, "FILE", "the bake file (for lit, indirect, probes and --diff)");
  io.option("--out,-o", a.out, "FILE", "output image: .png or .exr (linear cd/m^2); needed unless --explain");
  io.flag("--force", a.force, "preview a bake whose input hash does not match the scene");
  view.option("--mode", a.mode, "MODE", "lit, indirect, probes, albedo or normals")->capture_default_str();
  view.option("--camera", a.camera, "EYE,TARGET,UP", "9 numbers (unset: the glTF's camera, else a framing)");
  view.option("--camera-index", a.camera_index, "N", "which glTF camera without --camera")
      ->check(whole_number(0, 1 << 30))
      ->each([&a](const std::string&) { a.camera_index_given = true; })
      ->capture_default_str();
  view.option("--fov", a.fov, "DEG", "vertical field of view (unset: the glTF camera's, else 50)")
      ->check(field_of_view());
  view.option("--size", a.size, "WxH", "image size in pixels")->capture_default_str();
  view.option("--exposure", a.exposure, "EV100", "exposure (unset: automatic, from the mean luminance)");
  view.option("--volume", a.volume, "N", "only this DDGI volume (unset: every volume, blended)")
      ->check(whole_number(0, 1 << 20));
  ref.flag("--reference", a.reference, "write the converged path-traced reference to --out (no --bake needed)");
  ref.option("--spp", a.spp, "N", "reference samples per pixel")->check(whole_number(1, 1 << 24))->capture_default_str();
  ref.option("--seed", a.seed, "N", "reference random seed")->check(unsigned_integer())->capture_default_str();
  ref.option("--diff", a.diff, "FILE", "false-colour PNG of (lit - reference) / reference; prints the RMS");
  ref.option("--reference-image", a.reference_image, "EXR",
             "--diff with this EXR (an earlier --reference's), not a new render");
  ref.option("--block-map", a.block_map, "FILE", "PNG of --diff's 8x8 blocks: red brighter, blue darker than 10%");
  ref.option("--diff-floor", a.diff_floor, "F", "leave out pixels darker than F x the mean reference")
      ->check(non_negative_number())
      ->capture_default_str();
  ref.option("--check-patches", a.check_patches, "N", "reconstruction check at N blocks of this view; 0: off")
      ->capture_default_str();
  ref.option("--check-rays", a.check_rays, "N", "reference paths per point of --check-patches")->capture_default_str();
  ref.option("--check-noise", a.check_noise, "F", "trace patches noisier than this again; 0: one pass")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  ref.option("--check-ray-budget", a.check_ray_budget, "N", "mean paths a point, both passes [32x --check-rays]")
      ->check(CLI::Range(0u, 1u << 20));
  ref.option("--explain", a.explain, "X,Y", "why pixel X,Y reads what it does: its probes, weights, the truth");
  ref.option("--explain-paths", a.explain_paths, "N", "paths per path-traced irradiance of --explain")
      ->check(whole_number(16, 1 << 24))
      ->capture_default_str();
  sampler.option("--normal-bias", a.normal_bias, "M", "metres along the normal (unset: the loader's)")
      ->check(non_negative_number());
  sampler.option("--smooth-backface", a.smooth_backface, "F", "0 hard, 1 wrapped back-face weight (unset: loader's)")
      ->check(CLI::Range(0.f, 1.f));
  sampler
      .option("--behind-fade", a.behind_fade, "C",
              "probes behind the surface fade out by cosine -C (unset: 0.2; 0: off)")
      ->check(CLI::Range(0.f, 1.f));
  sampler.option("--visibility", a.visibility, "on|off", "Chebyshev visibility")->capture_default_str();
  sampler.option("--irradiance", a.irradiance, "atlas|sh", "probe irradiance from its atlas (if any) or its SH")
      ->capture_default_str();
  light.option("--sun", a.suns, "dx,dy,dz:lux[:r,g,b]", "directional light (unset: the bake's --sun)");
  light.option("--sky", a.sky, "R,G,B", "constant sky radiance, cd/m^2 (unset: the bake's --sky)");
  add_threads_option(&sub, a.threads, "images", "How it runs");
  run.option("--progress", a.progress, "MODE", "progress on stderr: auto, bar, lines or json")->capture_default_str();
}

Status to_settings(const PreviewArgs& a, PreviewSettings& s) {
  if (!parse_preview_mode(a.mode, s.mode) || s.mode == PreviewMode::Reference)
    return bad_arg("--mode", "expected lit, indirect, probes, albedo or normals (got '" + a.mode + "')");
  std::vector<double> wh;
  if (!parse_numbers(a.size, 'x', 2, wh) || wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384 ||
      wh[0] != std::floor(wh[0]) || wh[1] != std::floor(wh[1]))
    return bad_arg("--size", "expected WxH with integers 1..16384, got '" + a.size + "'");
  s.width = int(wh[0]);
  s.height = int(wh[1]);
  if (!a.camera.empty()) {
    std::vector<double> d;
    if (!parse_numbers(a.camera, ',', 9, d))
      return bad_arg("--camera", "expected eye,target,up as 9 numbers ex,ey,ez,tx,ty,tz,ux,uy,uz");
    GIBAKE_TRY(check_places("--camera", d, 0, 6, a.camera));
    GIBAKE_TRY(check_view_vectors("--camera", d, a.camera));
    std::vector<float> v(d.begin(), d.end());
    s.camera_given = true;
    s.eye = {v[0], v[1], v[2]};
    s.target = {v[3], v[4], v[5]};
    s.up = {v[6], v[7], v[8]};
  }
  s.fov_deg = a.fov;
  s.camera_index = a.camera_index;
  s.spp = a.spp;
  s.seed = a.seed;
  s.volume = a.volume;
  GIBAKE_TRY(parse_suns(a.suns, s.suns));
  if (!a.sky.empty()) GIBAKE_TRY(parse_vec3("--sky", a.sky, s.sky));
  return Status::ok();
}

// A bake of another scene (or of this one before it changed) would light it with the wrong probes.
Status check_bake_is_of_scene(const PreviewArgs& a, const loader::BakeFile& bake, const Scene& scene,
                              const Context& ctx) {
  BakeSceneMatch match;
  GIBAKE_TRY(match_bake_to_scene(bake, scene, match));
  if (match.matches) return Status::ok();
  const std::string what = "was not baked from " + a.scene + " as it is now (the bake's input hash " +
                           hash_text(match.bake_hash) + ", the scene's " + hash_text(match.scene_hash) +
                           ": another scene, or " + match.what() + ")";
  if (!a.force) return Status::error(ExitCode::BadArguments, a.bake, "--bake", what + "; --force previews it anyway");
  ctx.warning(a.bake + ": " + what + "; previewing anyway (--force)");
  return Status::ok();
}

// "1 camera (0..0)", "3 DDGI volumes (0..2)", "no camera": how many there are, and their indices.
std::string count_of(size_t n, const std::string& what) {
  if (n == 0) return "no " + what;
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s") + " (0.." + std::to_string(n - 1) + ")";
}

// --camera-index (never beside --camera: check_preview_args): one of the scene's cameras, not the
// framing of the scene bounds that a scene without that camera would get.
Status check_camera_index(const PreviewArgs& a, const Scene& scene) {
  if (!a.camera_index_given || a.camera_index < scene.cameras.size()) return Status::ok();
  return Status::error(ExitCode::BadArguments, a.scene, "--camera-index",
                       "asked for camera " + std::to_string(a.camera_index) + ", but the scene has " +
                           count_of(scene.cameras.size(), "glTF camera"));
}

// --volume names one of the bake's DDGI volumes: a wrong index is the argument's fault, not the
// file's. A bake of LPV cascades alone has none to pick (its views read the LPV whole), so an index
// there would go unused: refused too.
Status check_volume_index(const PreviewArgs& a, const loader::BakeFile& bake) {
  const size_t volumes = bake.ddgi_volumes().size();
  if (a.volume < 0 || size_t(a.volume) < volumes) return Status::ok();
  return Status::error(
      ExitCode::BadArguments, a.bake, "--volume",
      "asked for volume " + std::to_string(a.volume) + ", but the bake file has " + count_of(volumes, "DDGI volume"));
}

bool ends_with(const std::string& s, const char* e) {
  const std::string ext(e);
  if (s.size() < ext.size()) return false;
  std::string tail = s.substr(s.size() - ext.size());
  for (char& c : tail) c = char(std::tolower(static_cast<unsigned char>(c)));
  return tail == ext;
}

// Every check that needs no scene, the output paths included, so that nothing is imported for a
// preview that could not be written.
Status check_preview_args(const PreviewArgs& a, ProgressMode& pmode, PreviewSettings& settings, Tonemap& tm) {
  if (a.out.empty() && a.explain.empty())
    return bad_arg("--out", "an output image is required (--out view.png or .exr), or --explain X,Y");
  if (!a.out.empty() && !ends_with(a.out, ".png") && !ends_with(a.out, ".exr"))
    return Status::error(ExitCode::BadArguments, a.out, "--out", "expected a .png or .exr file name");
  if (!a.diff.empty() && !ends_with(a.diff, ".png"))
    return Status::error(ExitCode::BadArguments, a.diff, "--diff", "expected a .png file name");
  if (!a.block_map.empty() && !ends_with(a.block_map, ".png"))
    return Status::error(ExitCode::BadArguments, a.block_map, "--block-map", "expected a .png file name");
  GIBAKE_TRY(parse_progress_option(a.progress, pmode));
  GIBAKE_TRY(to_settings(a, settings));
  if (a.camera_index_given && settings.camera_given)
    return bad_arg("--camera-index", "picks a glTF camera, but --camera gives the view itself; give one of them");
  if (!std::isnan(a.exposure)) {
    if (!std::isfinite(a.exposure) || std::fabs(a.exposure) > 64) return bad_arg("--exposure", "EV100 must be within -64..64");
    tm.auto_exposure = false;
    tm.ev100 = float(a.exposure);
  }
  if (!a.explain.empty()) {
    if (a.bake.empty()) return bad_arg("--explain", "explains how a bake lights a pixel: it needs --bake");
    std::vector<double> xy;
    if (!parse_numbers(a.explain, ',', 2, xy) || xy[0] != std::floor(xy[0]) || xy[1] != std::floor(xy[1]) ||
        xy[0] < 0 || xy[1] < 0 || xy[0] >= settings.width || xy[1] >= settings.height)
      return bad_arg("--explain", "expected X,Y, a pixel of the " + std::to_string(settings.width) + "x" +
                                      std::to_string(settings.height) + " image (got '" + a.explain + "')");
  }
  // --reference alone renders no view of the bake: its lights come from --sun and --sky.
  const bool renders_view = !a.reference || !a.diff.empty();
  const bool needs_bake = (renders_view && (settings.mode == PreviewMode::Lit || settings.mode == PreviewMode::Indirect ||
                                            settings.mode == PreviewMode::Probes)) ||
                          !a.diff.empty();
  if (needs_bake && a.bake.empty())
    return bad_arg("--bake", std::string("mode '") + a.mode + "'" + (a.diff.empty() ? "" : " with --diff") +
                                 " needs the bake file (--bake probes.gibake)");
  if (!a.diff.empty() && settings.mode != PreviewMode::Lit)
    return bad_arg("--diff", "compares the lit view with the reference: use it with --mode lit");
  if (!a.block_map.empty() && a.diff.empty())
    return bad_arg("--block-map", "maps the blocks --diff compares: use it with --diff");
  if (!a.reference_image.empty() && (a.diff.empty() || a.reference))
    return bad_arg("--reference-image",
                   "is the reference --diff compares with: use it with --diff, without --reference");
  if (a.normal_bias >= 0.f) {  // metres, instead of the loader's bias in cells
    settings.sample.normal_bias = a.normal_bias;
    settings.sample.normal_bias_cells = 0.f;
  }
  if (a.smooth_backface >= 0.f) settings.sample.smooth_backface = a.smooth_backface;
  if (a.behind_fade >= 0.f) settings.sample.behind_fade = a.behind_fade;
  bool visibility = true;
  GIBAKE_TRY(parse_on_off("--visibility", a.visibility, visibility));
  settings.sample.use_visibility = visibility;
  if (a.irradiance != "atlas" && a.irradiance != "sh")
    return bad_arg("--irradiance", "expected atlas or sh, got '" + a.irradiance + "'");
  settings.sample.use_irradiance_atlas = a.irradiance == "atlas";
  if (a.check_patches > 0 && a.bake.empty())
    return bad_arg("--check-patches", "the reconstruction check needs the bake file (--bake probes.gibake)");
  std::vector<NamedPath> outputs;
  if (!a.out.empty()) outputs.push_back({"--out", a.out});
  if (!a.diff.empty()) outputs.push_back({"--diff", a.diff});
  if (!a.block_map.empty()) outputs.push_back({"--block-map", a.block_map});
  std::vector<NamedPath> read = scene_input_files(a.scene);
  if (!a.bake.empty()) read.push_back({"--bake", a.bake});
  if (!a.reference_image.empty()) read.push_back({"--reference-image", a.reference_image});
  return check_output_paths(outputs, read);
}

// The block measure of --diff: the share of 8x8 blocks within 10%, the reference's own noise on the
// same blocks, the blocks farthest off (for --explain) and, with --block-map, where they fail.
Status report_blocks(const PreviewArgs& a, const PreviewImage& view, const PreviewImage& ref,
                     const std::vector<std::string>& inputs) {
  BlockRatios ratios;
  GIBAKE_TRY(block_ratios(view, ref, kBlock, kBlockFloor, ratios));
  const BlockComparison blocks = block_comparison(ratios, kBlockWithin);
  std::printf("8x8 blocks: %.1f%% of %zu within 10%% of the reference; lit/reference p10 %.3f, median %.3f, p90 %.3f\n",
              100.0 * blocks.ratio.within, blocks.blocks, blocks.ratio.p10, blocks.ratio.median, blocks.ratio.p90);
  ReferenceNoise noise;
  if (ref.spp >= 2 && reference_noise(ref, kBlock, kBlockWithin, kBlockFloor, noise).is_ok() && noise.blocks > 0)
    std::printf(
        "reference noise (from its two halves): within 10%% of the truth on about %.0f%% of these blocks, "
        "median block error %.1f%%; a bake equal to the truth would score about that\n",
        100.0 * noise.within, 100.0 * noise.median_error);
  const std::vector<BlockAt> worst = worst_blocks(ratios, kBlockWithin, kWorstBlocks);
  if (!worst.empty()) {
    std::printf("worst 8x8 blocks (lit/reference; --explain X,Y at each block's centre):");
    for (const BlockAt& b : worst) std::printf(" %d,%d %.2f", b.x, b.y, b.ratio);
    std::printf("\n");
  }
  if (a.block_map.empty()) return Status::ok();
  std::vector<uint8_t> png;
  GIBAKE_TRY(encode_png(ref.width, ref.height, block_map_rgb8(ref, ratios, kBlockWithin), png));
  GIBAKE_TRY(write_file_atomic(a.block_map, png.data(), png.size(), inputs));
  std::fprintf(stderr, "gibake: wrote %s\n", a.block_map.c_str());
  return Status::ok();
}

// A reference with no pixel above --diff's floor compares nothing: figures of 0 would read as a
// perfect match. Judged before any image is written.
Status check_reference_compares(const PreviewArgs& a, const PreviewImage& view, const PreviewImage& ref) {
  PreviewDiff diff;
  GIBAKE_TRY(diff_previews(view, ref, a.diff_floor, diff, nullptr));
  if (diff.pixels > 0) return Status::ok();
  char what[160];
  std::snprintf(what, sizeof what, "no pixel brighter than %.4g cd/m^2: nothing to compare the view with",
                double(diff.floor));
  return Status::invalid(a.reference_image.empty() ? a.scene : a.reference_image, "reference", what);
}

// --diff: the false-colour difference of the lit view and the reference, its two figures and the
// 8x8-block comparison.
Status write_diff(const PreviewArgs& a, const PreviewImage& view, const PreviewImage& ref,
                  const std::vector<std::string>& inputs) {
  PreviewDiff diff;
  std::vector<uint8_t> rgb8, png;
  GIBAKE_TRY(diff_previews(view, ref, a.diff_floor, diff, &rgb8));
  GIBAKE_TRY(encode_png(view.width, view.height, rgb8, png));
  GIBAKE_TRY(write_file_atomic(a.diff, png.data(), png.size(), inputs));
  std::fprintf(stderr, "gibake: wrote %s\n", a.diff.c_str());
  // Two normalisations: the RMS divides by the reference's energy (bright pixels weigh most), the
  // mean divides each pixel by its own reference (dark pixels weigh as much): they differ.
  std::printf(
      "relative RMS %.4f = sqrt(sum (lit - ref)^2 / sum ref^2), bright pixels weigh most; "
      "mean |relative| %.4f = mean of |lit - ref| / ref, every pixel weighs the same; "
      "over %zu pixels with reference luminance > %.4g cd/m^2, %s\n",
      diff.rms, diff.mean_abs_relative, diff.pixels, double(diff.floor),
      ref.spp > 0 ? (std::to_string(ref.spp) + " spp").c_str() : "the given reference");
  return report_blocks(a, view, ref, inputs);
}

// --check-patches: the bake's reconstruction check at points this camera sees (the same measure
// as the blocks).
Status run_check(const PreviewArgs& a, const Scene& scene, const PreparedScene& prepared, const loader::BakeFile& bake,
                 const PreviewSettings& settings, const Context& ctx) {
  PreviewCamera cam;
  std::string described;
  GIBAKE_TRY(resolve_camera(scene, settings, cam, described));
  ReconstructionSettings rs;
  rs.patches = a.check_patches;
  rs.rays = a.check_rays;
  rs.target_noise = a.check_noise;
  rs.ray_budget = a.check_ray_budget;
  rs.seed = settings.seed;
  rs.cameras = {cam};
  rs.sample = settings.sample;
  rs.width = settings.width;
  rs.height = settings.height;
  TextureLod lod(scene, ctx);
  ReconstructionError error;
  const uint32_t only = uint32_t(std::max(settings.volume, 0));
  GIBAKE_TRY(measure_bake_reconstruction(prepared, lod, bake, settings.volume >= 0 ? &only : nullptr, rs, ctx, error));
  std::printf("%s\n", reconstruction_summary(error).c_str());
  return Status::ok();
}

// --explain: why one pixel of the view reads what it reads.
Status run_explain(const PreviewArgs& a, const PreparedScene& prepared, const loader::BakeFile& bake,
                   const PreviewSettings& settings, const Context& ctx) {
  std::vector<double> xy;
  parse_numbers(a.explain, ',', 2, xy);  // checked by check_preview_args
  ExplainSettings es;
  es.x = int(xy[0]);
  es.y = int(xy[1]);
  es.paths = a.explain_paths;
  ExplainedPixel pixel;
  GIBAKE_TRY(explain_pixel(prepared, bake, settings, es, ctx, pixel));
  std::printf("pixel %d,%d of the %dx%d view (%s)\n%s", es.x, es.y, pixel.width, pixel.height, pixel.camera.c_str(),
              explain_text(pixel).c_str());
  return Status::ok();
}

// The lit view and the reference that --out and --diff need, with what rendering them traced.
struct PreviewViews {
  PreviewImage view, ref;
  PreviewStats vstats, rstats;
  bool view_rendered = false, ref_rendered = false;
};

// The reference is read from --reference-image before anything renders (a wrong file fails at
// once), or rendered.
Status render_views(const PreviewArgs& a, const PreparedScene& prepared, const loader::BakeFile* bake,
                    const PreviewSettings& settings, const Context& ctx, PreviewViews& out) {
  out.view_rendered = !a.reference || !a.diff.empty();
  out.ref_rendered = (a.reference || !a.diff.empty()) && a.reference_image.empty();
  // Compared with the reference, the lit view integrates each pixel's area as the reference does
  // (4 x 4 points), so an edge or a texture's detail inside a block reads alike in both.
  PreviewSettings view_settings = settings;
  if (!a.diff.empty()) view_settings.pixel_grid = kDiffPixelGrid;
  if (!a.reference_image.empty())
    GIBAKE_TRY(read_reference_exr(a.reference_image, settings.width, settings.height, out.ref));
  if (out.view_rendered) GIBAKE_TRY(render_preview(prepared, bake, view_settings, ctx, out.view, &out.vstats));
  if (out.ref_rendered) {
    PreviewSettings rs = settings;
    rs.mode = PreviewMode::Reference;
    GIBAKE_TRY(render_preview(prepared, bake, rs, ctx, out.ref, &out.rstats));
  }
  return Status::ok();
}

// What was written, with which camera and exposure, and the rays each render traced.
void print_preview_summary(const PreviewArgs& a, const PreviewSettings& settings, const Tonemap& tm, float ev,
                           const PreviewViews& v) {
  const PreviewStats& main_stats = a.reference ? v.rstats : v.vstats;
  std::fprintf(stderr, "gibake: wrote %s (%s, %dx%d, %s", a.out.c_str(), a.reference ? "reference" : a.mode.c_str(),
               settings.width, settings.height, main_stats.camera.c_str());
  if ((a.reference ? v.ref : v.view).tonemapped())
    std::fprintf(stderr, ", exposure EV100 %.2f%s", ev, tm.auto_exposure ? " auto" : "");
  std::fprintf(stderr, ")\n");
  auto print_rays = [](const char* what, const PreviewStats& st) {
    std::fprintf(stderr, "  %s: %llu rays (%llu camera, %llu shadow, %llu bounce) in %.3f s, %.2f Mrays/s\n", what,
                 static_cast<unsigned long long>(st.total_rays()), static_cast<unsigned long long>(st.camera_rays),
                 static_cast<unsigned long long>(st.shadow_rays), static_cast<unsigned long long>(st.bounce_rays),
                 st.seconds, st.seconds > 0 ? double(st.total_rays()) / st.seconds / 1e6 : 0.0);
  };
  if (v.view_rendered) print_rays(a.mode.c_str(), v.vstats);
  if (v.ref_rendered) print_rays("reference", v.rstats);
  if (settings.mode == PreviewMode::Probes)
    std::fprintf(stderr, "  probes drawn: %d (%d inactive, magenta; %d relocated, yellow line to the grid point)\n",
                 v.vstats.probes_drawn, v.vstats.inactive_drawn, v.vstats.relocated_drawn);
}

int run_preview(const PreviewArgs& a) {
  ProgressMode pmode;
  PreviewSettings settings;
  Tonemap tm;
  if (Status st = check_preview_args(a, pmode, settings, tm); !st) return report_error(st);

  auto progress = std::make_shared<Progress>(pmode);
  Context ctx = progress_context(progress, a.threads);
  auto fail = [&](const Status& st) {
    progress->clear();
    return report_error(st);
  };

  Scene scene;
  if (Status st = import_scene(a.scene, ImportOptions{}, ctx, scene); !st) return fail(st);
  if (Status st = check_camera_index(a, scene); !st) return fail(st);
  loader::BakeFile bake;
  if (!a.bake.empty()) {
    if (Status st = open_bake_file(a.bake, bake, /*verify_checksums=*/true, /*probe_major_tiles=*/true); !st)
      return fail(st);
    if (Status st = check_values_readable(bake, a.bake); !st) return fail(st);
    if (Status st = check_volume_index(a, bake); !st) return fail(st);
    if (Status st = check_bake_is_of_scene(a, bake, scene, ctx); !st) return fail(st);
  }
  std::vector<std::string> inputs = scene.input_files;
  if (!a.bake.empty()) inputs.push_back(a.bake);
  if (!a.reference_image.empty()) inputs.push_back(a.reference_image);

  std::unique_ptr<PreparedScene> prepared;
  PrepareOptions po;
  po.blend_cutoff = settings.blend_cutoff;
  if (Status st = PreparedScene::create(scene, ctx, prepared, po); !st) return fail(st);
  const loader::BakeFile* bake_ptr = a.bake.empty() ? nullptr : &bake;

  if (!a.explain.empty()) {
    if (Status st = run_explain(a, *prepared, bake, settings, ctx); !st) return fail(st);
    if (a.out.empty()) return 0;
  }
  PreviewViews views;
  if (Status st = render_views(a, *prepared, bake_ptr, settings, ctx, views); !st) return fail(st);
  if (!a.diff.empty())
    if (Status st = check_reference_compares(a, views.view, views.ref); !st) return fail(st);
  float ev = 0.f;
  if (Status st = write_preview(a.out, a.reference ? views.ref : views.view, tm, inputs, &ev); !st) return fail(st);
  progress->clear();
  print_preview_summary(a, settings, tm, ev, views);
  if (!a.diff.empty()) {
    if (Status st = write_diff(a, views.view, views.ref, inputs); !st) return fail(st);
  }
  if (a.check_patches > 0) {
    if (Status st = run_check(a, scene, *prepared, bake, settings, ctx); !st) return fail(st);
  }
  return 0;
}

}  // namespace

const Command kPreviewCommand{"preview", add_command<PreviewArgs, preview_options, run_preview>};

}  // namespace gibake::cli
