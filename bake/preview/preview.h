// Preview renders of a scene and its bake (`gibake preview`, the bake report): Embree primary
// rays from a pinhole camera, one per pixel centre, shaded as
//   lit        albedo x (direct punctual light with shadow rays + baked irradiance E_ind)/pi + emission
//              E_ind is read with the runtime loader's CPU sampler (loader::BakeFile::sample_ddgi: every
//              DDGI volume blended; DdgiVolume::sample_irradiance with --volume N) at the hit with the
//              shading normal, exactly as an engine reads the file.
//   indirect   E_ind / pi: the radiance a white Lambertian surface would reflect from the bake alone
//   probes     the lit view with every probe drawn over it as a sphere shaded by its SH, E(n)/pi;
//              inactive probes flat magenta, relocated probes with a yellow line to their grid point.
//              Probes are drawn through geometry (those inside walls and solids are the ones to see).
//   albedo     the Lambertian albedo (rho), not tonemapped
//   normals    the shading normal facing the camera, (n + 1) / 2, not tonemapped
//   reference  the path tracer of the bake's path-traced gather (trace_radiance: direct + every
//              bounce until Russian roulette ends the path, same materials, lights, sky and texture
//              footprints), spp samples per pixel spread over the pixel's area (a box filter, as
//              Cycles integrates a pixel). Its path length is never the bake's: a yardstick that
//              shared the bake's truncation could not see it.
// Values are cd/m^2 (photometric, DESIGN.md) except albedo and normals. Misses show the sky.
// Deterministic: one pixel's value depends only on the inputs and the seed, not on threads.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "bake/trace/path_gather.h"
#include "gibake/loader.hpp"
#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

enum class PreviewMode : uint8_t { Lit = 0, Indirect, Probes, Albedo, Normals, Reference };

// "lit", "indirect", "probes", "albedo", "normals", "reference"; false for anything else.
bool parse_preview_mode(const std::string& text, PreviewMode& out);
const char* preview_mode_name(PreviewMode mode);

// Where the baked irradiance is read: every DDGI volume of a file blended (BakeFile::sample_ddgi;
// outside every volume the nearest one's clamped answer, as one volume always gave), or one volume.
struct DdgiReader {
  const loader::BakeFile* file = nullptr;
  const loader::DdgiVolume* volume = nullptr;  // set: this volume alone
  DdgiReader(const loader::BakeFile& f) : file(&f) {}     // NOLINT: implicit on purpose
  DdgiReader(const loader::DdgiVolume& v) : volume(&v) {}  // NOLINT
  loader::Rgb sample(const loader::Vec3& p, const loader::Vec3& n, const loader::SampleOptions& o) const {
    if (volume) return volume->sample_irradiance(p, n, o);
    loader::Rgb e;
    file->sample_ddgi(p, n, e, o);
    return e;
  }
  std::vector<const loader::DdgiVolume*> volumes() const {
    std::vector<const loader::DdgiVolume*> v;
    if (volume) v.push_back(volume);
    else
      for (const loader::DdgiVolume& d : file->ddgi_volumes()) v.push_back(&d);
    return v;
  }
};

struct PreviewSettings {
  PreviewMode mode = PreviewMode::Lit;
  int width = 1280, height = 720;
  // Camera: explicit eye/target/up when camera_given; else scene.cameras[camera_index] (the
  // glTF's first camera by default); else a view from above one corner that frames the bounds.
  bool camera_given = false;
  std::array<float, 3> eye{0.f, 0.f, 0.f}, target{0.f, 0.f, -1.f}, up{0.f, 1.f, 0.f};
  float fov_deg = 0.f;  // vertical field of view; 0: the glTF camera's, else 50 degrees
  size_t camera_index = 0;
  // Lighting added to the scene's own KHR_lights_punctual lights. With lights_from_bake, the
  // bake file's recorded --sun and --sky settings (metadata "settings") are used when these are
  // empty, so a preview is lit like the bake.
  std::vector<SunLight> suns;
  std::array<float, 3> sky{0.f, 0.f, 0.f};  // constant sky radiance, cd/m^2
  std::string sky_hdr;
  float sky_hdr_scale = 1.f;
  bool lights_from_bake = true;
  float blend_cutoff = kDefaultBlendCutoff;
  // -1: every DDGI volume of the bake file, blended as an engine blends them (BakeFile::sample_ddgi,
  // docs/FORMAT.md "Several volumes"); N: only volume N (its own sampler, clamped to its grid).
  int32_t volume = -1;
  loader::SampleOptions sample;      // how E_ind is read (loader defaults: what an engine does)
  // Lit and indirect: an n x n grid of points a pixel, averaged (1: the pixel's centre). A view
  // compared with the reference takes more than one, so that both integrate the same pixel area.
  int pixel_grid = 1;
  // Reference: samples per pixel, path length (converged: path_gather.h) and seed.
  int spp = 64;
  int bounces = kReferenceBounces;
  int roulette_depth = 3;
  uint64_t seed = 0;
  float probe_radius = 0.f;  // metres; 0: 0.15 x the smallest grid spacing
  bool probes_depth_tested = false;  // probes mode: hide probes behind the scene's surfaces (the report)
};

// The bake's recorded lighting (metadata "settings": suns, sky, sky map, blend cutoff) copied
// into `s` where `s` leaves them empty. Never its path length: the reference converges.
void apply_bake_lighting(const loader::BakeFile& bake, PreviewSettings& s, const Context& ctx);
// The same from a bake's settings JSON (what its file's metadata "settings" will hold).
void apply_settings_lighting(const std::string& settings_json, PreviewSettings& s, const Context& ctx);

// A rendered view. `rgb` is linear (cd/m^2, or rho / (n+1)/2 for albedo and normals);
// `overlay` (probes mode) holds display colours 0xAABBGGRR drawn over the tonemapped image
// (alpha 0: none) for inactive probes, relocation lines and outlines.
struct PreviewImage {
  int width = 0, height = 0;
  PreviewMode mode = PreviewMode::Lit;
  std::vector<float> rgb;
  std::vector<uint32_t> overlay;
  // Reference with spp >= 2: the mean of each pixel's first spp / 2 samples (rgb holds all of
  // them), from which the reference's own noise is estimated (reference_noise); empty otherwise.
  std::vector<float> first_half_rgb;
  int spp = 0;  // reference: the samples per pixel behind rgb
  bool tonemapped() const { return mode != PreviewMode::Albedo && mode != PreviewMode::Normals; }
};

struct PreviewStats {
  uint64_t camera_rays = 0, shadow_rays = 0, bounce_rays = 0;
  uint64_t total_rays() const { return camera_rays + shadow_rays + bounce_rays; }
  double seconds = 0.0;       // rendering only (scene preparation excluded)
  double prepare_seconds = 0.0;
  std::string camera;         // which camera was used, for the user
  std::array<float, 3> eye{}, forward{}, up{};
  float fov_deg = 0.f;
  int probes_drawn = 0, inactive_drawn = 0, relocated_drawn = 0;
};

// Where the camera sits and looks (resolved from the settings and the scene).
struct PreviewCamera {
  kernels::float3 eye, forward, right, up;  // orthonormal
  float tan_half = 0.f;                     // tan(vertical fov / 2)
  float aspect = 1.f;
  // Pixel (x, y) of a world point, false when it is behind the camera.
  bool project(const kernels::float3& p, int width, int height, float& px, float& py) const;
  // The unit direction through point (fx, fy) of a width x height image, in pixels from its
  // top-left corner (a pixel's centre is x + 0.5, y + 0.5).
  kernels::float3 ray(float fx, float fy, int width, int height) const;
};
Status resolve_camera(const Scene& scene, const PreviewSettings& settings, PreviewCamera& camera,
                      std::string& description);

// Renders settings.mode. `bake` is required for lit, indirect and probes (null: InvalidInput),
// ignored otherwise. The second form reuses a prepared scene (e.g. several views of one bake).
// The sky and punctual lights of a preview's settings (the scene's own lights, --sun, --sky).
Status make_preview_lights(const Scene& scene, const PreviewSettings& settings, Sky& sky,
                           std::vector<kernels::ShadeLight>& lights);

Status render_preview(const Scene& scene, const loader::BakeFile* bake, const PreviewSettings& settings,
                      const Context& ctx, PreviewImage& out, PreviewStats* stats = nullptr);
Status render_preview(const PreparedScene& prepared, const loader::BakeFile* bake, const PreviewSettings& settings,
                      const Context& ctx, PreviewImage& out, PreviewStats* stats = nullptr);

// ---- Images (bake/preview/preview_image.cpp) ----
//
// Tonemap (lit, indirect, probes, reference): luminance Y = 0.2126 R + 0.7152 G + 0.0722 B;
// exposure in EV100 (Lagarde & de Rousiers 2014): scaled = value / (1.2 x 2^EV100); the automatic
// exposure is EV100 = log2(Y_avg x 100 / 12.5) with Y_avg the geometric mean luminance of the
// pixels with Y > 0; then the ACES filmic fit of Narkowicz (2015),
// f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) clamped to [0, 1], per channel; then the
// sRGB transfer function, 8 bits. Albedo is sRGB-encoded without exposure or curve; normals are
// written as (n + 1) / 2 without any transfer function.
struct Tonemap {
  bool auto_exposure = true;
  float ev100 = 0.f;  // used when !auto_exposure
};
float auto_ev100(const PreviewImage& image);
// 8-bit RGB, overlay applied. `ev_used` (optional) receives the exposure applied.
std::vector<uint8_t> tonemap_rgb8(const PreviewImage& image, const Tonemap& tonemap, float* ev_used = nullptr);
// PNG bytes of 8-bit RGB (stb_image_write).
Status encode_png(int width, int height, const std::vector<uint8_t>& rgb8, std::vector<uint8_t>& png);
// Writes `.png` (tonemapped) or `.exr` (linear float RGB; overlay pixels as their linear colour)
// atomically, refusing to overwrite any of `inputs`. Other extensions: BadArguments.
Status write_preview(const std::string& path, const PreviewImage& image, const Tonemap& tonemap,
                     const std::vector<std::string>& inputs = {}, float* ev_used = nullptr);

// A reference image read back (`preview --reference-image`): an EXR of the view with linear R, G, B
// in cd/m^2, `width` x `height` pixels: one that `--reference --out F.exr` wrote (which keeps its
// first half's mean and its samples a pixel, so its noise is known again) or another renderer's
// (spp 0: its noise unknown). InvalidInput naming the file and the place otherwise (a pixel that is
// not a finite, non-negative value included); IoFailure when it cannot be opened.
Status read_reference_exr(const std::string& path, int width, int height, PreviewImage& out);

// Difference between a baked-GI view (lit) and its reference. Relative RMS:
//   rms = sqrt( sum (Y_test - Y_ref)^2 / sum Y_ref^2 )
// over the pixels whose reference luminance exceeds `floor` = floor_fraction x the mean
// reference luminance (so black background and shadowed-to-zero pixels do not divide by ~0).
// `false_colour`: per pixel (Y_test - Y_ref) / max(Y_ref, floor), blue (-50% or less) through
// white (0) to red (+50% or more); pixels below the floor dark grey.
struct PreviewDiff {
  double rms = 0.0;
  double mean_abs_relative = 0.0;  // mean |Y_test - Y_ref| / Y_ref over the counted pixels
  size_t pixels = 0;               // counted
  float floor = 0.f;
};
Status diff_previews(const PreviewImage& test, const PreviewImage& reference, float floor_fraction, PreviewDiff& diff,
                     std::vector<uint8_t>* false_colour_rgb8 = nullptr);

// Small helpers shared with the report.
std::string base64_encode(const std::vector<uint8_t>& bytes);

}  // namespace gibake
