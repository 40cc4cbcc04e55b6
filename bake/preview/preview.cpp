// Preview renders (see preview.h): camera, per-pixel shading, probe overlay.
#include "bake/preview/preview.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <nlohmann/json.hpp>

#include "bake/run/arena.h"
#include "bake/scene/emitters.h"
#include "bake/scene/lights.h"
#include "bake/scene/material.h"
#include "bake/scene/sky.h"
#include "bake/scene/texture_lod.h"
#include "bake/trace/path_gather.h"
#include "bake/trace/probe_rays.h"
#include "kernels/ray_gen.h"
#include "io/timer.h"

namespace gibake {
using kernels::float3;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kTile = 16;
constexpr uint32_t kMagenta = 0xFFFF00FFu, kYellow = 0xFF00E0FFu, kBlack = 0xFF000000u;

float3 f3(const std::array<float, 3>& a) { return float3{a[0], a[1], a[2]}; }

Status bad(const std::string& where, const std::string& what) {
  return Status::error(ExitCode::BadArguments, "", where, what);
}

// Probe spheres (SH-shaded) and overlay marks drawn over the lit image.
// `scene_depth`: the distance to the scene along each pixel's ray (kInf on a miss), so that a probe
// behind a wall or under the floor stays hidden as the scene's own surfaces would hide it.
// `zbuf` starts as the scene depth and keeps the spheres drawn, so several volumes' probes hide
// one another as they should; `img.overlay` is sized by the caller.
void draw_probes(const loader::DdgiVolume& vol, const PreviewCamera& cam, const PreviewSettings& s,
                 std::vector<float>& zbuf, PreviewImage& img, PreviewStats& stats) {
  const int W = img.width, H = img.height;
  const auto& d = vol.desc();
  float min_spacing = kInf;
  for (int a = 0; a < 3; ++a)
    if (d.counts[a] > 1 && d.spacing[a] > 0.f) min_spacing = std::min(min_spacing, d.spacing[a]);
  if (!std::isfinite(min_spacing)) min_spacing = 1.f;
  const float radius = s.probe_radius > 0.f ? s.probe_radius : 0.15f * min_spacing;
  const float ring = radius * 1.2f;
  const uint32_t coeffs = vol.sh_coefficients();
  std::vector<float> sh(size_t(coeffs) * 3);
  auto put = [&](int x, int y, uint32_t c) {
    if (x >= 0 && y >= 0 && x < W && y < H) img.overlay[size_t(y) * W + x] = c;
  };
  auto line = [&](float x0, float y0, float x1, float y1, uint32_t c) {
    const int n = int(std::ceil(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0)))) + 1;
    if (n > 8 * (W + H)) return;
    for (int i = 0; i <= n; ++i) {
      const float t = float(i) / float(n);
      put(int(std::floor(x0 + (x1 - x0) * t)), int(std::floor(y0 + (y1 - y0) * t)), c);
    }
  };
  for (uint32_t p = 0; p < vol.probe_count(); ++p) {
    const auto pos = vol.probe_position(p);
    const float3 c{pos[0], pos[1], pos[2]};
    const uint32_t state = vol.state(p);
    const auto rest = vol.probe_rest_position(vol.probe_coord(p));
    const float3 r{rest[0], rest[1], rest[2]};
    const bool moved = kernels::length(c - r) > 1e-5f;
    float px, py;
    if (!cam.project(c, W, H, px, py)) continue;
    ++stats.probes_drawn;
    if (state == GIBAKE_PROBE_INACTIVE) ++stats.inactive_drawn;
    if (moved) {
      ++stats.relocated_drawn;
      float rx, ry;
      if (cam.project(r, W, H, rx, ry)) {
        line(px, py, rx, ry, kYellow);
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) put(int(rx) + dx, int(ry) + dy, kYellow);
      }
    }
    // Screen rectangle of the outline sphere: its distance along the view axis bounds the size.
    const float z = kernels::dot(c - cam.eye, cam.forward);
    if (z <= ring) continue;
    const float pix_per_m = float(H) / (2.f * cam.tan_half * (z - ring));
    const int half = int(std::ceil(ring * pix_per_m)) + 2;
    if (half > 4 * (W + H)) continue;
    vol.sh_probe(p, sh.data());
    const int x0 = std::max(0, int(px) - half), x1 = std::min(W - 1, int(px) + half);
    const int y0 = std::max(0, int(py) - half), y1 = std::min(H - 1, int(py) + half);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const float3 dir = cam.ray(float(x) + 0.5f, float(y) + 0.5f, W, H);
        const float3 oc = cam.eye - c;
        const float b = kernels::dot(oc, dir);
        const float dist2 = kernels::dot(oc, oc) - b * b;  // squared distance of the ray from c
        if (dist2 > ring * ring) continue;
        const size_t i = size_t(y) * W + x;
        const float t = -b - std::sqrt(std::max(0.f, ring * ring - dist2));
        if (t <= 0.f || t >= zbuf[i]) continue;
        zbuf[i] = t;
        if (dist2 > radius * radius) {
          img.overlay[i] = kBlack;  // outline
          continue;
        }
        const float th = -b - std::sqrt(radius * radius - dist2);
        const float3 n = kernels::normalize(cam.eye + dir * th - c);
        if (state == GIBAKE_PROBE_INACTIVE) {
          img.overlay[i] = kMagenta;
          continue;
        }
        img.overlay[i] = 0u;
        const loader::Rgb e = loader::sh_irradiance(sh.data(), coeffs, {n.x, n.y, n.z});
        for (int k = 0; k < 3; ++k) img.rgb[i * 3 + k] = e[size_t(k)] / kernels::kPi;
      }
  }
}

}  // namespace

namespace {

void apply_lighting(const nlohmann::json& st, PreviewSettings& s, const Context& ctx) {
  try {
    if (s.suns.empty() && st.contains("suns"))
      for (const auto& sun : st["suns"]) {
        SunLight l;
        l.direction = sun.at("direction").get<std::array<float, 3>>();
        l.lux = sun.at("lux").get<float>();
        l.color = sun.at("color").get<std::array<float, 3>>();
        s.suns.push_back(l);
      }
    if (s.sky == std::array<float, 3>{0.f, 0.f, 0.f} && st.contains("sky"))
      s.sky = st["sky"].get<std::array<float, 3>>();
    if (s.sky_hdr.empty() && st.contains("sky_hdr")) {
      s.sky_hdr = st["sky_hdr"].get<std::string>();
      if (st.contains("sky_hdr_scale")) s.sky_hdr_scale = st["sky_hdr_scale"].get<float>();
    }
    if (st.contains("blend_cutoff")) s.blend_cutoff = st["blend_cutoff"].get<float>();
  } catch (const std::exception& e) {
    ctx.warning(std::string("bake metadata settings unreadable, lighting from the command line only: ") + e.what());
  }
}

}  // namespace

void apply_bake_lighting(const loader::BakeFile& bake, PreviewSettings& s, const Context& ctx) {
  const std::string meta = bake.metadata_json();
  if (meta.empty()) return;
  const nlohmann::json j = nlohmann::json::parse(meta, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("settings") || !j["settings"].is_object()) return;
  apply_lighting(j["settings"], s, ctx);
}

void apply_settings_lighting(const std::string& settings_json, PreviewSettings& s, const Context& ctx) {
  const nlohmann::json st = nlohmann::json::parse(settings_json, nullptr, false);
  if (st.is_discarded() || !st.is_object()) return;
  apply_lighting(st, s, ctx);
}

bool parse_preview_mode(const std::string& text, PreviewMode& out) {
  static const char* const names[] = {"lit", "indirect", "probes", "albedo", "normals", "reference"};
  for (int i = 0; i < 6; ++i)
    if (text == names[i]) {
      out = PreviewMode(i);
      return true;
    }
  return false;
}

const char* preview_mode_name(PreviewMode mode) {
  static const char* const names[] = {"lit", "indirect", "probes", "albedo", "normals", "reference"};
  return names[int(mode)];
}

bool PreviewCamera::project(const float3& p, int width, int height, float& px, float& py) const {
  const float3 v = p - eye;
  const float z = kernels::dot(v, forward);
  if (z <= 1e-6f) return false;
  const float sx = kernels::dot(v, right) / (z * tan_half * aspect), sy = kernels::dot(v, up) / (z * tan_half);
  px = (sx + 1.f) * 0.5f * float(width);
  py = (1.f - sy) * 0.5f * float(height);
  return std::isfinite(px) && std::isfinite(py);
}

float3 PreviewCamera::ray(float fx, float fy, int width, int height) const {
  const float sx = (2.f * fx / float(width) - 1.f) * tan_half * aspect;
  const float sy = (1.f - 2.f * fy / float(height)) * tan_half;
  return kernels::normalize(forward + right * sx + up * sy);
}

Status resolve_camera(const Scene& scene, const PreviewSettings& s, PreviewCamera& cam, std::string& description) {
  if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
    return bad("--size", "width and height must be between 1 and 16384");
  if (!(s.fov_deg >= 0.f && s.fov_deg < 179.f)) return bad("--fov", "field of view must be in (0, 179) degrees");
  float3 eye, fwd, up;
  float fov = s.fov_deg > 0.f ? s.fov_deg * kernels::kPi / 180.f : 50.f * kernels::kPi / 180.f;
  if (s.camera_given) {
    eye = f3(s.eye);
    fwd = kernels::normalize(f3(s.target) - eye);
    up = kernels::normalize(f3(s.up));
    if (kernels::length(fwd) == 0.f) return bad("--camera", "eye and target must differ");
    description = "camera from --camera";
  } else if (s.camera_index < scene.cameras.size()) {
    const Camera& c = scene.cameras[s.camera_index];
    eye = f3(c.position);
    fwd = f3(c.forward);
    up = f3(c.up);
    if (s.fov_deg <= 0.f) fov = c.yfov;
    description = "glTF camera " + std::to_string(s.camera_index) + (c.name.empty() ? "" : " '" + c.name + "'");
  } else {
    if (scene.bounds.empty()) return Status::invalid(scene.source_path, "scene", "no geometry to frame");
    const float3 lo = f3(scene.bounds.min), hi = f3(scene.bounds.max);
    const float3 centre = (lo + hi) * 0.5f;
    const float radius = std::max(0.5f * kernels::length(hi - lo), 1e-3f);
    fwd = kernels::normalize(float3{-0.55f, -0.45f, -0.7f});
    eye = centre - fwd * (radius / std::sin(0.5f * fov) * 1.02f);
    up = float3{0.f, 1.f, 0.f};
    description = "framing the scene bounds (no glTF camera)";
  }
  cam.forward = kernels::normalize(fwd);
  cam.right = kernels::normalize(kernels::cross(cam.forward, up));
  if (kernels::length(cam.right) == 0.f) {  // up parallel to the view: pick any perpendicular
    const float3 alt = std::fabs(cam.forward.y) < 0.9f ? float3{0.f, 1.f, 0.f} : float3{1.f, 0.f, 0.f};
    cam.right = kernels::normalize(kernels::cross(cam.forward, alt));
  }
  cam.up = kernels::cross(cam.right, cam.forward);
  cam.eye = eye;
  cam.tan_half = std::tan(0.5f * fov);
  cam.aspect = float(s.width) / float(s.height);
  return Status::ok();
}

Status make_preview_lights(const Scene& scene, const PreviewSettings& s, Sky& sky,
                           std::vector<kernels::ShadeLight>& lights) {
  sky = Sky();
  sky.constant = f3(s.sky);
  if (!s.sky_hdr.empty()) {
    GIBAKE_TRY(load_sky_exr(s.sky_hdr, sky));
    sky.scale = s.sky_hdr_scale;
  }
  lights = shade_lights(scene, s.suns);
  return Status::ok();
}

Status render_preview(const Scene& scene, const loader::BakeFile* bake, const PreviewSettings& settings,
                      const Context& ctx, PreviewImage& out, PreviewStats* stats) {
  const Stopwatch prepare_time;
  std::unique_ptr<PreparedScene> prepared;
  PrepareOptions po;
  po.blend_cutoff = settings.blend_cutoff;
  GIBAKE_TRY(PreparedScene::create(scene, ctx, prepared, po));
  const double prep = prepare_time.seconds();
  GIBAKE_TRY(render_preview(*prepared, bake, settings, ctx, out, stats));
  if (stats) stats->prepare_seconds = prep;
  return Status::ok();
}

namespace {

bool mode_reads_bake(PreviewMode mode) {
  return mode == PreviewMode::Lit || mode == PreviewMode::Indirect || mode == PreviewMode::Probes;
}

// The reader a mode that reads the bake shades with: the DDGI volumes (all of them, or --volume's),
// or none for a bake of LPV cascades alone, whose lit and indirect views read the LPV sampler.
Status open_bake(const loader::BakeFile* bake, const PreviewSettings& s, std::optional<DdgiReader>& ddgi) {
  if (!mode_reads_bake(s.mode)) return Status::ok();
  if (!bake) return bad("--bake", std::string("mode '") + preview_mode_name(s.mode) + "' needs a bake file");
  const bool lpv_only = bake->ddgi_volumes().empty() && !bake->lpv_cascades().empty();
  if (lpv_only && s.mode == PreviewMode::Probes)
    return bad("--mode",
               "the bake holds LPV cascades and no DDGI probes: there are no probes to draw (use lit or "
               "indirect)");
  if (lpv_only) return Status::ok();
  const size_t volumes = bake->ddgi_volumes().size();
  // A valid file of another kind (voxel GI alone): the wrong file for this command, not a bad one.
  if (volumes == 0)
    return bad("--bake",
               "the bake file holds neither DDGI probes nor LPV cascades to light a view with (voxel GI "
               "alone: 'gibake sample --source vxgi' reads it)");
  if (s.volume >= 0 && size_t(s.volume) >= volumes)
    return Status::invalid("", "--volume",
                           "the bake file has " + std::to_string(volumes) + " DDGI volume(s), asked for volume " +
                               std::to_string(s.volume));
  if (s.volume >= 0)
    ddgi.emplace(bake->ddgi_volumes()[size_t(s.volume)]);
  else
    ddgi.emplace(*bake);
  return Status::ok();
}

Status check_sampling(const PreviewSettings& s) {
  if (s.spp < 1 || s.spp > 1 << 20) return bad("--spp", "samples per pixel must be between 1 and 1048576");
  if (s.pixel_grid < 1 || s.pixel_grid > 16) return bad("pixel grid", "must be between 1 and 16");
  if (s.bounces < 0 || s.bounces > kReferenceBounces)
    return bad("--bounces", "must be between 0 and " + std::to_string(kReferenceBounces));
  return Status::ok();
}

// What one pixel of a preview reads: a camera ray shaded as the mode asks, or the path-traced
// reference over the pixel's area. Pixels are independent; each writes only its own entries of
// `depth` and `out`.
struct PixelShader {
  const PreparedScene& prepared;
  const PreviewSettings& s;
  const PreviewCamera& cam;
  const Sky& sky;
  const TraceSetup& setup;
  const PathSetup& path;
  const loader::BakeFile* bake;
  const std::optional<DdgiReader>& ddgi;
  const TextureLod& lod;
  std::vector<float>& depth;  // the scene's distance per pixel, for the probes' overlay (empty: not kept)
  PreviewImage& out;

  bool shaded() const { return s.mode != PreviewMode::Albedo && s.mode != PreviewMode::Normals; }
  float3 camera_ray(float fx, float fy) const { return cam.ray(fx, fy, s.width, s.height); }

  // The baked irradiance at p (lux): the DDGI sampler, or the LPV's.
  float3 baked_irradiance(const float3& p, const float3& n) const {
    const loader::Rgb e = ddgi ? ddgi->sample({p.x, p.y, p.z}, {n.x, n.y, n.z}, s.sample)
                               : bake->sample_lpv({p.x, p.y, p.z}, {n.x, n.y, n.z});
    return float3{e[0], e[1], e[2]};
  }

  // One camera ray through (fx, fy) of pixel (x, y), shaded as the mode asks.
  float3 point(float fx, float fy, int x, int y, TraceCounters& tc) const {
    const Scene& scene = prepared.scene();
    const float3 dir = camera_ray(fx, fy);
    const TraceHit hit = prepared.intersect(cam.eye, dir, 0.f, kInf);
    ++tc.rays;
    if (!depth.empty() && hit.t >= 0.f) depth[size_t(y) * size_t(s.width) + size_t(x)] = hit.t;
    if (hit.t < 0.f) return (shaded() && s.mode != PreviewMode::Indirect) ? sky.radiance(dir) : float3{};
    const Material& mat = hit_material(scene, hit);
    const float3 ng = hit.front ? hit.ng : -hit.ng;
    const float3 p = cam.eye + dir * hit.t;
    const SurfaceSample surf =
        hit_surface(scene, hit, TextureFootprint{&lod, setup.cone_spread * hit.t, kernels::dot(dir, ng)});
    float3 n = kernels::dot(surf.normal, surf.normal) == 0.f ? ng : surf.normal;
    if (kernels::dot(n, ng) < 0.f) n = -n;
    if (s.mode == PreviewMode::Albedo) return surf.albedo;
    if (s.mode == PreviewMode::Normals) return (n + float3{1.f, 1.f, 1.f}) * 0.5f;
    if (!hit.front && !mat.double_sided) return float3{};  // inside a single-sided surface: black, as the bake
    const float3 e_ind = baked_irradiance(p, n);
    if (s.mode == PreviewMode::Indirect) return e_ind * (1.f / kernels::kPi);
    const float3 shadow_org = offset_origin(setup, p, ng);
    const float3 direct = shade_punctual(setup, shadow_org, n, ng, surf.albedo, surf.emission, 0.f, tc, nullptr);
    return direct + surf.albedo * e_ind * (1.f / kernels::kPi);
  }

  // The pixel's whole area, as a renderer with a one-pixel box filter integrates it: a pixel that
  // an edge or a texture's detail crosses then reads its mean, not its centre's value. The first
  // half of the samples is kept apart, for the reference's own noise.
  float3 reference(int x, int y, TraceCounters& tc) const {
    const int half_spp = s.spp / 2;
    float3 sum{};
    const uint64_t pixel = uint64_t(y) * uint64_t(s.width) + uint64_t(x);
    for (int k = 0; k < s.spp; ++k) {
      const uint64_t key = kernels::rng_hash(s.seed, pixel, uint64_t(k), 0x7072657669657755ull);
      const uint64_t at = kernels::rng_hash(s.seed, pixel, uint64_t(k), 0x7069786a69747465ull);
      const float3 d = camera_ray(float(x) + kernels::rng_uniform(at, 0), float(y) + kernels::rng_uniform(at, 1));
      sum += trace_radiance(path, cam.eye, d, key, tc);
      if (k + 1 == half_spp) kernels::store3(&out.first_half_rgb[pixel * 3], sum * (1.f / float(half_spp)));
    }
    return sum * (1.f / float(s.spp));
  }

  float3 pixel(int x, int y, TraceCounters& tc) const {
    if (s.mode == PreviewMode::Reference) return reference(x, y, tc);
    const bool area = s.pixel_grid > 1 && (s.mode == PreviewMode::Lit || s.mode == PreviewMode::Indirect);
    if (!area) return point(float(x) + 0.5f, float(y) + 0.5f, x, y, tc);
    // An n x n grid of points over the pixel: the same pixel area the reference integrates.
    float3 sum{};
    const int n = s.pixel_grid;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        sum += point(float(x) + (float(i) + 0.5f) / float(n), float(y) + (float(j) + 0.5f) / float(n), x, y, tc);
    return sum * (1.f / float(n * n));
  }
};

// Every pixel, in tiles over the arena's threads; the rays counted into `stats`.
void render_tiles(const PixelShader& shader, const Context& ctx, tbb::task_arena& arena, PreviewStats& stats) {
  const PreviewSettings& s = shader.s;
  const int W = s.width, H = s.height;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int tiles_total = tiles_x * tiles_y;
  std::atomic<int> tiles_done{0};
  tbb::enumerable_thread_specific<TraceCounters> counters;
  const char* stage = s.mode == PreviewMode::Reference ? "reference" : "preview";
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range2d<int>(0, tiles_y, 1, 0, tiles_x, 1), [&](const tbb::blocked_range2d<int>& r) {
      TraceCounters& tc = counters.local();
      for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
        for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx) {
          for (int y = ty * kTile; y < std::min(H, (ty + 1) * kTile); ++y)
            for (int x = tx * kTile; x < std::min(W, (tx + 1) * kTile); ++x)
              kernels::store3(&shader.out.rgb[(size_t(y) * W + x) * 3], shader.pixel(x, y, tc));
          const int done = ++tiles_done;
          if (done % 16 == 0 || done == tiles_total) ctx.report(stage, done, tiles_total);
        }
    });
  });
  for (const TraceCounters& tc : counters) {
    stats.camera_rays += tc.rays;
    stats.shadow_rays += tc.shadow_rays;
    stats.bounce_rays += tc.bounce_rays;
  }
}

void camera_stats(const PreviewCamera& cam, PreviewStats& stats) {
  stats.eye = {cam.eye.x, cam.eye.y, cam.eye.z};
  stats.forward = {cam.forward.x, cam.forward.y, cam.forward.z};
  stats.up = {cam.up.x, cam.up.y, cam.up.z};
  stats.fov_deg = 2.f * std::atan(cam.tan_half) * 180.f / kernels::kPi;
}

}  // namespace

Status render_preview(const PreparedScene& prepared, const loader::BakeFile* bake, const PreviewSettings& in,
                      const Context& ctx, PreviewImage& out, PreviewStats* stats_out) {
  const Scene& scene = prepared.scene();
  PreviewSettings s = in;
  if (bake && s.lights_from_bake) apply_bake_lighting(*bake, s, ctx);
  std::optional<DdgiReader> ddgi;
  GIBAKE_TRY(open_bake(bake, s, ddgi));
  GIBAKE_TRY(check_sampling(s));
  PreviewCamera cam;
  PreviewStats stats;
  GIBAKE_TRY(resolve_camera(scene, s, cam, stats.camera));
  Sky sky;
  std::vector<kernels::ShadeLight> lights;
  GIBAKE_TRY(make_preview_lights(scene, s, sky, lights));

  const bool reference = s.mode == PreviewMode::Reference;
  TextureLod lod;
  if (s.mode != PreviewMode::Normals) lod = TextureLod(scene, ctx);
  TraceSetup setup;
  setup.prepared = &prepared;
  setup.sky = &sky;
  setup.lights = lights.data();
  setup.light_count = int(lights.size());
  setup.random_light = false;
  setup.seed = s.seed;
  setup.lod = &lod;
  // The reference reads every texel at full resolution, as a path tracer such as Cycles does (its
  // samples integrate the pixel); the other modes read a pixel's footprint, as an engine does.
  setup.cone_spread = reference ? 0.f : 2.f * cam.tan_half / float(s.height);
  EmitterTable emitters;
  if (reference) emitters = EmitterTable(scene);
  PathSetup path;
  path.trace = setup;
  path.emitters = &emitters;
  path.bounces = s.bounces;
  path.roulette_depth = s.roulette_depth;

  const size_t pixels = size_t(s.width) * size_t(s.height);
  out = PreviewImage();
  out.width = s.width;
  out.height = s.height;
  out.mode = s.mode;
  out.rgb.assign(pixels * 3, 0.f);
  out.spp = reference ? s.spp : 0;
  if (reference && s.spp / 2 > 0) out.first_half_rgb.assign(out.rgb.size(), 0.f);
  std::vector<float> depth(s.mode == PreviewMode::Probes && s.probes_depth_tested ? pixels : 0, kInf);
  const PixelShader shader{prepared, s, cam, sky, setup, path, bake, ddgi, lod, depth, out};
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  const Stopwatch render_time;  // the tiles and the probes' overlay, as the rays' rate reports them
  render_tiles(shader, ctx, *arena, stats);
  if (s.mode == PreviewMode::Probes) {
    std::vector<float> zbuf = depth;
    zbuf.resize(pixels, kInf);
    out.overlay.assign(pixels, 0u);
    for (const loader::DdgiVolume* v : ddgi->volumes()) draw_probes(*v, cam, s, zbuf, out, stats);
  }
  stats.seconds = render_time.seconds();
  camera_stats(cam, stats);
  if (stats_out) *stats_out = stats;
  return Status::ok();
}

}  // namespace gibake
