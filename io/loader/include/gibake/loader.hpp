// gibake runtime loader: reads and validates bake files (gibake/format.h, docs/FORMAT.md), gives
// typed views of their sections and samples their light on the CPU. C++17 standard library only.
//
// Contract:
//  * Input: any bytes. Every entry point is safe on malformed or hostile input: it gives an Error
//    (or, for a view, zeros), never a crash or a read outside the file.
//  * Units (docs/DESIGN.md): world space is glTF's (right-handed, +Y up, metres); radiance in cd/m^2
//    (SH coefficients, voxel faces, cone results), irradiance in lux (the sample_* answers), LPV
//    cells in cd. Directions and normals are unit vectors in world space. A Lambertian surface of
//    albedo rho under irradiance E shows radiance rho E / pi: that is what an engine shades with.
//  * Lifetime: DdgiVolume, LpvCascade and VxgiVolume are views into their BakeFile's bytes; they,
//    and the pointers they return, are valid while that BakeFile lives and is not reopened. With
//    open_borrowed the caller's buffer must outlive the BakeFile.
//  * Threads: after open() returns, every const member function may be called from any number of
//    threads at once (nothing is cached or mutated); open() itself needs exclusive access.
//  * What an engine must do: sample at the shaded point itself with its unit surface normal (the
//    sampler adds the normal bias of SampleOptions, so do not offset the point yourself); with several DDGI
//    volumes call BakeFile::sample_ddgi (finer volumes win where they hold the point, see
//    ddgi_priority()); on the GPU, use gibake/ddgi_sample.glsl and gibake/vxgi_cone.glsl, which
//    compute the same values as this loader.
//
// Example: irradiance at a point, and the diffuse radiance it gives.
//
//   gibake::loader::BakeFile file;
//   if (gibake::loader::Error err = file.open("scene.gibake")) {
//     std::fprintf(stderr, "%s\n", err.message.c_str());  // err.code says which check failed
//     return;
//   }
//   gibake::loader::Rgb e;  // lux
//   const gibake::loader::Vec3 p{1.f, 0.5f, -2.f}, n{0.f, 1.f, 0.f};  // metres; unit normal
//   if (file.sample_ddgi(p, n, e))  // false: p lies outside every DDGI volume
//     for (int c = 0; c < 3; ++c) radiance[c] = albedo[c] * e[c] / 3.14159265f;  // cd/m^2
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gibake/format.h"

namespace gibake::loader {

enum class ErrorCode : int {
  Ok = 0,
  IoError,             // the file could not be opened or read
  Truncated,           // the file is shorter than its header or its recorded size
  BadMagic,            // not a gibake file
  UnsupportedVersion,  // a major version this loader does not know
  BadHeader,           // header fields out of range (header size, file size, flags)
  HeaderChecksum,      // header bytes do not match header_checksum
  BadSectionTable,     // section table outside the file or misaligned, or an entry's reserved fields set
  TableChecksum,       // section table bytes do not match table_checksum
  SectionOutOfRange,   // a section's bytes lie outside the file
  SectionMisaligned,   // a section's offset is not 16-aligned
  SectionOverlap,      // two sections (or a section and the header/table) overlap
  BadElementFormat,    // unknown/unsupported element format for the type, or size != count*elem
  SectionChecksum,     // section payload does not match its checksum
  BadVolume,           // inconsistent volume description or section counts
  MissingSection,      // a required section (e.g. DDGI SH for a volume) is absent
  DuplicateSection,    // the same section type twice in one group
  BadPadding,          // a non-zero padding byte, a gap the layout does not explain, or bytes after the end
};

const char* error_code_name(ErrorCode code);

struct Error {
  ErrorCode code = ErrorCode::Ok;
  std::string message;  // e.g. "section 2 (ddgi_sh): checksum mismatch"
  bool ok() const { return code == ErrorCode::Ok; }
  explicit operator bool() const { return !ok(); }  // true when there is an error
};

struct LoadOptions {
  // Header, table and section checksums. Structure is validated either way; turn this off only for
  // bytes already verified (it reads every byte of the file once).
  bool verify_checksums = true;
  // Also keep each active DDGI probe's depth and irradiance tiles in one contiguous block (the
  // atlases' texels in the file's precision, irradiance without its alpha), so that the CPU
  // sampler reads a probe's tile from one place instead of from one atlas row per texel row. The
  // answers are the same to the bit; large volumes sample several times faster (the atlases' rows
  // are far apart in memory). Costs about active probes x (depth texels x 4 + irradiance texels x 6)
  // bytes at binary16 (twice that for float32 atlases): DdgiVolume::probe_tile_bytes().
  bool probe_major_tiles = false;
};

const char* section_type_name(uint32_t type);    // "ddgi_sh", ..., "unknown"
const char* element_format_name(uint32_t format);  // "f32", "rgba16f", ..., "unknown"

// XXH64 (classic 64-bit xxHash), the checksum used throughout the format.
uint64_t xxh64(const void* data, size_t size, uint64_t seed = 0);
// IEEE binary16 conversions (round to nearest even; values above 65504 become infinity).
float half_to_float(uint16_t h);
uint16_t float_to_half(float f);
// Shared-exponent RGB (GIBAKE_FORMAT_RGB9E5, format 1.5) <-> binary32. Encoding rounds each
// mantissa to nearest (GL_EXT_texture_shared_exponent's rule) after clamping to [0, 65408]; NaN
// becomes 0. Decoding is exact.
std::array<float, 3> rgb9e5_to_float(uint32_t packed);
uint32_t float_to_rgb9e5(float r, float g, float b);
constexpr float kRgb9e5Max = 65408.f;  // (511 / 512) * 2^16

using Rgb = std::array<float, 3>;
using Vec3 = std::array<float, 3>;

// How DdgiVolume::sample_irradiance weighs the 8 probes around a point. The defaults are those the
// bake's own checks use and those of the GLSL sampler (gibake_default_sample_options()).
struct SampleOptions {
  // In [0, 1]. 1: wrap-shading backface weight ((dot(dir_to_probe, N)+1)/2)^2 + 0.2, never zero,
  // smooth across surfaces; 0: hard saturate(dot(dir_to_probe, N)). Values between blend the two.
  float smooth_backface = 1.f;
  // The surface point is pushed along N by max(normal_bias, normal_bias_cells x the volume's
  // smallest probe spacing) before probes are weighed. The bias must be a fraction of a cell: the
  // probes recorded the depth of the surface itself, and a point biased by millimetres sits on that
  // depth, so the Chebyshev test half-occludes it and the surface reads far too dark (in places too
  // bright; docs/BENCHMARKS.md has the reconstruction figures). Engines pass the unbiased point and
  // leave these at their defaults.
  float normal_bias = 0.001f;      // metres, >= 0; the floor of the bias
  float normal_bias_cells = 0.3f;  // of the smallest spacing; 0: normal_bias alone
  float variance_floor = 1e-4f;    // m^2, lower bound of the Chebyshev variance
  float min_weight = 1e-6f;        // floor of backface*visibility, so a point never goes black
  bool use_visibility = true;      // Chebyshev test against the depth-moment atlas when present
  // A probe's irradiance from its irradiance atlas when the volume has one (each texel the
  // cosine-weighted mean of the probe's rays around its normal), else from its SH. The SH's two
  // bands ring: a bright source below a surface's horizon (a sunlit floor seen from a probe beside
  // it) reaches normals that cannot see it, and in sunlit scenes that is the largest error of the
  // SH. false: always the SH.
  bool use_irradiance_atlas = true;
  // A probe behind the surface's tangent plane at the point (cosine c < 0 between N and the
  // direction to the probe) has its backface weight scaled by saturate(1 + c / behind_fade): it
  // fades out within asin(behind_fade) of the plane (about 12 degrees at 0.2) and weighs nothing
  // past it. Such a probe sees the surface's far side (the sunlit flank of a pillar beside its
  // shaded face, the lit side of a fold); only the normal bias lifts the point into its sight, and
  // its light leaks in. 0: off (DDGI's weights).
  float behind_fade = 0.2f;
};

// One probe's part in DdgiVolume::try_sample_irradiance at a point (DdgiVolume::probe_weights):
// the factors of its weight, so a tool can say why a point reads what it reads.
struct ProbeWeight {
  uint32_t probe = 0;      // index in the volume
  float distance = 0.f;    // metres from the biased point to the probe
  float backface = 0.f;    // SampleOptions::smooth_backface's weight, times behind_fade's
  float visibility = 1.f;  // Chebyshev weight from the depth moments (1 without them)
  float trilinear = 0.f;   // the probe's trilinear weight in its cell
  float weight = 0.f;      // max(backface x visibility, min_weight) x trilinear: what the sampler sums
};

// One texel of a probe's bilinear lookup in its irradiance atlas tile (DdgiVolume::irradiance_texels):
// atlas coordinates (border included) and the texel's bilinear weight.
struct AtlasTexel {
  uint32_t x = 0, y = 0;
  float weight = 0.f;
};

// One volume's share of BakeFile::sample_ddgi at a point (BakeFile::ddgi_shares).
struct VolumeShare {
  uint32_t volume = 0;  // index into BakeFile::ddgi_volumes()
  float share = 0.f;    // its part of the answer; the shares sum to 1
};

// GibakeDdgiVolume of the GLSL sampler (gibake/ddgi_sample.glsl): 96 bytes, the same in std140
// and std430, for a uniform or storage buffer.
struct GlslDdgiVolume {
  float grid_min[4];    // xyz, w 0
  float spacing[4];     // xyz; w: the RGB9E5 irradiance atlas's irradiance_scale, else 0
  int32_t counts[4];    // xyz, w sh_coefficients
  // depth_tile, tile_border, atlas_planes_per_row (resolved; a sparse volume's atlas_tiles_per_row);
  // w: bit 0 set with a depth atlas, bit 1 set for a sparse volume, bits 8-23 the irradiance tile
  // (interior texels a side; 0 without an irradiance atlas)
  uint32_t atlas[4];
  // element formats of ddgi_sh, ddgi_states (0: none), ddgi_depth; w: bit 0 set with offsets, bits
  // 8-15 the ddgi_irradiance format (0 without an irradiance atlas)
  uint32_t formats[4];
  uint32_t engine[4];   // the includer's; 0 here
};
static_assert(sizeof(GlslDdgiVolume) == 96, "GibakeDdgiVolume is 96 bytes");

// A view of one DDGI volume inside a BakeFile (valid while the BakeFile lives).
class DdgiVolume {
 public:
  const gibake_ddgi_volume& desc() const { return desc_; }
  uint32_t probe_count() const { return desc_.probe_count; }
  // A sparse volume (1.5, GIBAKE_DDGI_FLAG_SPARSE) stores only some of its probes; every call
  // below still takes the probe's index in the grid and answers as a dense volume would, a probe
  // not stored being inactive (zero SH, offset and stats). Its section payloads are in slot order.
  bool sparse() const { return (desc_.flags & GIBAKE_DDGI_FLAG_SPARSE) != 0; }
  uint32_t stored_probes() const { return sparse() ? desc_.stored_probes : desc_.probe_count; }
  // The probe's index in the per-probe sections and the atlases' slot order: the probe itself in a
  // dense volume, GIBAKE_PROBE_SLOT_NONE for a probe a sparse volume does not store (or out of range).
  uint32_t slot(uint32_t probe) const;
  uint32_t sh_coefficients() const { return desc_.sh_coefficients; }
  uint32_t sh_format() const { return sh_.format; }
  bool has_sh() const { return sh_.data != nullptr; }
  bool has_offsets() const { return offsets_.data != nullptr; }
  bool has_states() const { return states_.data != nullptr; }
  bool has_stats() const { return stats_.data != nullptr; }
  bool has_irradiance() const { return irradiance_.data != nullptr; }
  bool has_depth() const { return depth_.data != nullptr; }

  // SH of incident radiance (cd/m^2), coefficient-major RGB triplets, converted to float.
  float sh(uint32_t probe, uint32_t coefficient, uint32_t channel) const;
  void sh_probe(uint32_t probe, float* out) const;  // sh_coefficients()*3 floats
  Vec3 offset(uint32_t probe) const;                 // zero when there is no offsets section
  uint32_t state(uint32_t probe) const;              // GIBAKE_PROBE_ACTIVE when absent
  gibake_probe_stats stats(uint32_t probe) const;    // zeros when absent
  std::array<float, 4> irradiance_texel(uint32_t x, uint32_t y) const;  // lux RGBA
  std::array<float, 2> depth_texel(uint32_t x, uint32_t y) const;       // mean, mean^2

  std::array<int32_t, 3> probe_coord(uint32_t index) const;
  // Atlas layout: k Y-planes side by side per band of tile rows (format.h), and the top-left
  // texel (border included) of a probe's tile in an atlas of `interior`-texel tiles. In a sparse
  // volume the stored probe of slot s has the tile at column s mod T, row s div T (T:
  // desc().atlas_tiles_per_row); a probe not stored has the column one past the atlas's last, so
  // that the texel calls read zeros there.
  uint32_t atlas_planes_per_row() const;
  std::array<uint32_t, 2> tile_origin(uint32_t probe, uint32_t interior) const;
  // The same place in tiles (column, row) for the probe at grid coordinate `coord`: the origin is
  // it times the bordered tile's side in either atlas.
  std::array<uint32_t, 2> tile_cell(const std::array<int32_t, 3>& coord) const;
  Vec3 probe_rest_position(const std::array<int32_t, 3>& coord) const;
  Vec3 probe_position(uint32_t index) const;  // rest position + relocation offset
  // Irradiance (lux) of one probe's SH for surface normal n (unit), clamped >= 0.
  Rgb sh_irradiance(uint32_t probe, const Vec3& n) const;
  // Irradiance (lux) of one probe's irradiance atlas tile for surface normal n (unit), bilinear
  // inside its bordered tile; zero without an irradiance atlas.
  Rgb atlas_irradiance(uint32_t probe, const Vec3& n) const;
  // The 4 texels atlas_irradiance sums for normal n, in its order with their weights; 0 without an
  // irradiance atlas (or for a probe out of range), else 4.
  uint32_t irradiance_texels(uint32_t probe, const Vec3& n, AtlasTexel out[4]) const;
  // DDGI irradiance (lux) at world point p with unit normal n: 8 probes, trilinear, backface and
  // Chebyshev weights, inactive probes skipped; the probes' irradiance atlas texels at n weighted and
  // normalised (or their weighted SH normalised, then E(n): SampleOptions::use_irradiance_atlas).
  Rgb sample_irradiance(const Vec3& p, const Vec3& n, const SampleOptions& options = {}) const;
  // The same into `out`; false (and zero) when no probe of the 8 weighs in (all inactive, or the
  // volume has no SH): the volume has no answer at p.
  bool try_sample_irradiance(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& options = {}) const;
  // The same, with `sight`: the largest back-face x visibility weight of the probes weighed (before
  // SampleOptions::min_weight), 0 where no probe weighs in. Near 0, no probe of the cell sees p and
  // the answer is the floor's: the blend of several volumes trusts the volume that much less.
  bool try_sample_irradiance(const Vec3& p, const Vec3& n, Rgb& out, float& sight,
                             const SampleOptions& options = {}) const;
  // The probes that try_sample_irradiance weighs at p (active, weight > 0), in its order, into
  // `out`; returns how many (0: the volume has no answer at p).
  uint32_t probe_weights(const Vec3& p, const Vec3& n, ProbeWeight out[8], const SampleOptions& options = {}) const;
  // Several volumes (BakeFile::sample_ddgi, docs/FORMAT.md "Several volumes"). With g = (p -
  // grid_min) / spacing and m = min(g, last - g) (spacings inside the probe box, negative outside),
  // the weight at p is the product over axes of saturate(2 (1 + m)): 1 in the probe box and its cells
  // (placement puts one probe at the centre of each cell, so the cell box, half a spacing beyond
  // the outermost probes, is what the volume was placed for), falling linearly to 0 at one spacing
  // beyond the outermost probe layer. The region, where the weight can be positive, is the probe
  // box grown by one spacing. An axis of one probe (or spacing 0) is unbounded (weight 1 along it),
  // as the sampler reads its one layer for any coordinate.
  float blend_weight(const Vec3& p) const;
  bool region_contains(const Vec3& p) const;    // inside the closed region
  float region_distance(const Vec3& p) const;   // metres from p to the region; 0 inside
  // Blend priority: the smallest spacing of an axis with more than one probe; infinity with none.
  float finest_spacing() const;
  // What the GLSL sampler needs: the volume parameters, and the section-table index of the
  // volume's section of a type (GIBAKE_SECTION_DDGI_*; -1 when absent) whose payload
  // (BakeFile::section_data, sections()[i].size bytes) an engine uploads as it is.
  GlslDdgiVolume glsl_volume() const;
  int32_t section_index(uint32_t section_type) const;
  // Bytes of the probe-major tile copies (LoadOptions::probe_major_tiles); 0 without them.
  size_t probe_tile_bytes() const;
  // A probe's block of the depth or irradiance copy (side x side texels of the tile, border
  // included, row by row; (mean, mean^2) or (r, g, b)), null without one (the sampler then reads the
  // atlas), and the bytes of one element there (2: binary16, 4: float32; 0 without copies).
  const uint8_t* probe_tile(uint32_t probe, bool depth) const;
  uint32_t probe_tile_element_bytes(bool depth) const;

 private:
  friend class BakeFile;
  friend class LpvCascade;
  friend class VxgiVolume;
  struct View {
    const uint8_t* data = nullptr;
    uint32_t format = 0;
    uint32_t section = 0;
  };
  // Probe-major copies of the atlases (LoadOptions::probe_major_tiles), owned by the BakeFile.
  struct ProbeTiles {
    static constexpr uint32_t kNone = 0xFFFFFFFFu;
    std::vector<uint32_t> block;  // per probe: its block of tiles, kNone for an inactive probe
    // Per block, side x side texels, row by row: (mean, mean^2) / (r, g, b); elements of
    // depth_bytes / irradiance_bytes bytes (2: binary16, 4: float32); empty without that atlas.
    std::vector<uint8_t> depth, irradiance;
    uint32_t depth_bytes = 0, irradiance_bytes = 0;
  };
  void build_probe_tiles(ProbeTiles& tiles) const;
  gibake_ddgi_volume desc_{};
  View sh_, offsets_, states_, stats_, irradiance_, depth_, slots_;
  uint32_t volume_section_ = 0;
  const ProbeTiles* tiles_ = nullptr;
};

// A view of one light propagation volume cascade (format 1.2) inside a BakeFile.
class LpvCascade {
 public:
  const gibake_lpv_cascade& desc() const { return desc_; }
  uint32_t cell_count() const { return desc_.cell_count; }
  uint32_t sh_format() const { return sh_.format; }
  uint32_t section() const { return section_; }  // table index of the lpv_cascade section
  // Radiant-intensity SH (cd) of cell `cell`, channel 0..2 (R,G,B), coefficient 0..3.
  float sh(uint32_t cell, uint32_t channel, uint32_t coefficient) const;
  void cell_sh(uint32_t cell, float out[12]) const;  // [channel][coefficient]
  uint32_t cell_index(int32_t x, int32_t y, int32_t z) const;
  Vec3 cell_centre(int32_t x, int32_t y, int32_t z) const;
  bool contains(const Vec3& p) const;  // inside [grid_min, grid_min + dims * cell_size]
  // Irradiance (lux, >= 0) on a surface with unit normal n from 12 SH values of this cascade:
  // E = [pi c0 Y00 + 2pi/3 sum_m c1m Y1m(-n)] / cell_size^2.
  Rgb irradiance_from_sh(const float sh[12], const Vec3& n) const;
  // Trilinear over cell centres (clamped to the outermost centres), then irradiance_from_sh.
  Rgb sample_irradiance(const Vec3& p, const Vec3& n) const;

 private:
  friend class BakeFile;
  gibake_lpv_cascade desc_{};
  DdgiVolume::View sh_;
  uint32_t section_ = 0;
};

// A view of one voxel-GI volume (format 1.3; one clipmap) inside a BakeFile. Faces are numbered
// +X, -X, +Y, -Y, +Z, -Z (0..5); face f holds the light leaving a voxel through its f side (what a
// viewer on that side sees), premultiplied by the voxel's opacity as seen from there (format.h).
using Rgba = std::array<float, 4>;
class VxgiVolume {
 public:
  const gibake_vxgi_volume& desc() const { return desc_; }
  uint32_t levels() const { return desc_.levels; }
  uint32_t radiance_format() const { return radiance_.format; }
  uint32_t section() const { return section_; }  // table index of the vxgi_volume section
  bool has_sdf() const { return sdf_.data != nullptr; }
  std::array<int32_t, 3> level_dims(uint32_t level) const;
  float level_voxel_size(uint32_t level) const;
  uint64_t level_offset(uint32_t level) const;  // first element of the level in the radiance section
  // One texel (zero outside the level's grid or for an unknown level/face).
  Rgba texel(uint32_t level, uint32_t face, int32_t x, int32_t y, int32_t z) const;
  // Trilinear over the level's voxel centres at world point p, clamped to the outermost centres
  // (a GPU's clamp-to-edge: a wall at the volume's border keeps its opacity up to the border).
  // With `dir` (a cone's unit direction), along an axis it travels nearly along (|dir| >= 0.9) the farther texel's
  // colour is seen through the nearer one's alpha, so a wall hides what lies behind it.
  Rgba sample(uint32_t level, uint32_t face, const Vec3& p, const Vec3* dir = nullptr) const;
  uint32_t faces() const { return desc_.faces; }  // 6, or 22 with the 16 precomputed cone slices
  // A precomputed cone slice (faces 6..21, baked with --vxgi-precompute-cones): slice 6+i holds
  // sum_a d_a^2 x (the face facing back at d = precomputed_cone_directions()[i] on axis a), so one
  // trilinear sample stands for sample_cone's three; fractional `lod` as sample_cone.
  Rgba sample_slice(float lod, uint32_t face, const Vec3& dir, const Vec3& p) const;
  // What a cone travelling along unit `dir` sees at p: the three faces facing it (face +X when
  // dir.x < 0), weighted by dir.x^2, dir.y^2, dir.z^2 (they sum to 1, so no direction gets more
  // light than an axis), at fractional mip level `lod` (linear between the two levels).
  Rgba sample_cone(float lod, const Vec3& dir, const Vec3& p) const;
  // Distance (m) from p to the nearest opaque level-0 voxel (trilinear), or 0 without an SDF.
  float sdf(const Vec3& p) const;
  float sdf_texel(int32_t x, int32_t y, int32_t z) const;  // one stored value; 0 outside or without an SDF
  bool contains(const Vec3& p) const;  // inside [grid_min, grid_min + dims * voxel_size]

 private:
  friend class BakeFile;
  gibake_vxgi_volume desc_{};
  DdgiVolume::View radiance_, sdf_;
  uint32_t section_ = 0;
};

// Elements of a volume's vxgi_radiance section: 6 faces x the voxels of every stored level.
uint64_t vxgi_radiance_count(const gibake_vxgi_volume& desc);

// A file's clipmaps, finest first (BakeFile::vxgi_volumes()), or one volume: what the cone tracer
// reads. Clipmap k+1 has twice the voxel size of clipmap k and the same voxel counts.
struct VxgiClipmaps {
  const VxgiVolume* volumes = nullptr;
  size_t count = 0;
  VxgiClipmaps(const VxgiVolume& v) : volumes(&v), count(1) {}                                // NOLINT: implicit on purpose
  VxgiClipmaps(const std::vector<VxgiVolume>& v) : volumes(v.data()), count(v.size()) {}      // NOLINT
  const VxgiVolume& operator[](size_t k) const { return volumes[k]; }
};

// Cone tracing (VXGI's ConeTrace, io/loader/src/vxgi_cone.cpp; docs/FORMAT.md "Cone tracer").
// The cone belongs to the finest clipmap containing p (its voxel size v0 sets the offsets below).
// It starts at p + n * start_offset * v0, takes its first sample one v0 further along dir, and
// steps by step_scale * its diameter (at least v0 / 2; with an SDF, at least the free distance
// minus the cone's radius), compositing front to back until alpha >= alpha_stop or it leaves the
// coarsest clipmap (then the sky). Each sample reads the finest clipmap whose box holds the
// sample's footprint, at the mip level of the footprint (level 0 when that clipmap is coarser);
// within two texels of that clipmap's border it blends towards the next coarser one (a lerp
// between clipmap levels), so no seam shows where a cone crosses from one to the next.
struct ConeOptions {
  float step_scale = 1.f;    // step = step_scale * cone diameter; > 0
  float start_offset = 1.f;  // level-0 voxels along n before the cone starts (self-occlusion); >= 0
  float alpha_stop = 0.99f;  // in (0, 1]: the cone stops once this opaque
  float max_distance = 0.f;  // metres; 0: until the cone leaves the volume
  bool use_sdf = true;       // skip empty space with the SDF when the volume has one
  bool calibrated = true;    // cone_trace_diffuse: apply the volume's fitted diffuse_scale
  // Texel size (and step) at most this fraction of the distance travelled, so that trilinear
  // samples never reach back to the surface the cone leaves; 0: footprint = diameter.
  float self_occlusion_limit = 0.5f;
  uint32_t diffuse_cones = 6;  // cone_trace_diffuse: 6 (the 60-degree set) or N > 6 cosine-spiral cones
  // cone_trace_diffuse: the 16 precomputed cone directions instead (those of
  // precomputed_cone_directions() with cos > 0 to n, aperture 0.872665 rad, weights pi cos / sum cos),
  // reading the precomputed slices where the volume has them (faces() == 22), else the three faces.
  bool precomputed_cones = false;
  // Deprecated name of precomputed_cones, kept for engines written against it: either one set
  // selects the precomputed set. (No [[deprecated]]: GCC would warn on every default-constructed
  // ConeOptions.)
  bool seed_cones = false;
};
// The 16 precomputed cone directions (unit, world space): the directions of a volume's slices
// 6..21 (slice 6 + i is direction i) and of ConeOptions::precomputed_cones. The four cube
// diagonals, then twelve more spread evenly over the sphere.
const std::array<Vec3, 16>& precomputed_cone_directions();
[[deprecated("use precomputed_cone_directions()")]] inline const std::array<Vec3, 16>& seed_diffuse_cones() {
  return precomputed_cone_directions();
}
struct ConeResult {
  Rgb radiance{0.f, 0.f, 0.f};  // cd/m^2, composited
  float alpha = 0.f;
  uint32_t steps = 0;
};
// One cone of full apex angle `aperture` (radians) along unit `dir` from p (normal n).
// `slice` (6..21): read that precomputed cone slice instead of the three faces (0: the faces).
ConeResult cone_trace(const VxgiClipmaps& v, const Vec3& p, const Vec3& n, const Vec3& dir, float aperture,
                      const ConeOptions& options = {}, uint32_t slice = 0);
// Irradiance (lux) on a surface at p with unit normal n: 6 cones of 60 degrees (one along n, five
// at 60 degrees from it), weighted by the cosine-weighted solid angle of the hemisphere part each
// stands for (pi/4 and 3 pi/20, summing to pi: a uniform radiance L gives exactly pi L), times the
// volume's diffuse_scale (fitted by the bake against its path tracer) unless options.calibrated is off.
Rgb cone_trace_diffuse(const VxgiClipmaps& v, const Vec3& p, const Vec3& n, const ConeOptions& options = {});
// Radiance (cd/m^2) reflected towards `to_eye` (unit, from p towards the viewer): one cone along
// the mirror direction with aperture max(0.05, roughness * pi / 2) radians.
ConeResult cone_trace_specular(const VxgiClipmaps& v, const Vec3& p, const Vec3& n, const Vec3& to_eye, float roughness,
                               const ConeOptions& options = {});
// The diffuse cone set in n's frame: directions and weights (6 each).
void diffuse_cones(const Vec3& n, Vec3 dirs[6], float weights[6]);

// Evaluates E(n) = sum_l A_l sum_m L_lm Y_lm(n) for `coefficients` (4 or 9) RGB coefficients.
Rgb sh_irradiance(const float* sh, uint32_t coefficients, const Vec3& n);
// Octahedral encoding of a unit direction into [-1,1]^2 (z is the hemisphere axis).
std::array<float, 2> encode_oct(const Vec3& dir);

// Blend priority of DDGI volumes (BakeFile::ddgi_priority()): indices into `volumes`, the smallest
// spacing of an axis with more than one probe first (a volume with none counts as the coarsest),
// ties in the given order.
std::vector<uint32_t> ddgi_priority_order(const std::vector<gibake_ddgi_volume>& volumes);
// The ddgi_volume_index section (format 1.4, docs/FORMAT.md "Volume index") for these volumes in
// file order: its U32 words, header first. Empty for fewer than two volumes (files with one volume
// carry no index). Cubic cells over the union of the regions (an axis of one probe spans the other
// volumes' extent), edge the smallest region edge of any volume, doubled until at most
// GIBAKE_DDGI_INDEX_MAX_CELLS cells; a cell lists every volume whose region grown by cell_size/16
// meets it, in priority order (the margin covers float rounding of the lookup and of the region test).
std::vector<uint32_t> build_ddgi_volume_index(const std::vector<gibake_ddgi_volume>& volumes);

// A view of a file's ddgi_volume_index (valid while the BakeFile lives): which volumes a point's
// cell lists, for BakeFile::sample_ddgi and for engines that upload it (section()).
class DdgiVolumeIndex {
 public:
  bool present() const { return words_ != nullptr; }
  const gibake_ddgi_volume_index& desc() const { return desc_; }
  int32_t section() const { return present() ? int32_t(section_) : -1; }  // its table index
  // The cell holding p; false outside the index grid (or without an index).
  bool cell_of(const Vec3& p, uint32_t& cell) const;
  uint32_t list_size(uint32_t cell) const;            // 0 for a cell out of range
  uint32_t list_id(uint32_t cell, uint32_t k) const;  // k < list_size(cell): a ddgi_volumes() index
  uint32_t word(uint64_t i) const;                    // word i of the section (0 beyond it)

 private:
  friend class BakeFile;
  gibake_ddgi_volume_index desc_{};
  const uint8_t* words_ = nullptr;
  uint64_t word_count_ = 0;
  uint32_t section_ = 0;
};

class BakeFile {
 public:
  BakeFile() = default;
  BakeFile(const BakeFile&) = delete;
  BakeFile& operator=(const BakeFile&) = delete;
  BakeFile(BakeFile&&) = default;
  BakeFile& operator=(BakeFile&&) = default;

  Error open(const std::string& path, const LoadOptions& options = {});
  Error open(std::vector<uint8_t>&& bytes, const LoadOptions& options = {});  // takes ownership
  Error open_borrowed(const void* data, size_t size, const LoadOptions& options = {});

  const gibake_file_header& header() const { return header_; }
  const std::vector<gibake_section_entry>& sections() const { return sections_; }
  const uint8_t* section_data(uint32_t index) const;  // nullptr when out of range
  const std::vector<DdgiVolume>& ddgi_volumes() const { return volumes_; }
  // LPV cascades sorted by cascade_index (finest first); empty when the file has none.
  const std::vector<LpvCascade>& lpv_cascades() const { return lpv_; }
  // LPV irradiance (lux) at p for unit normal n from the finest cascade containing p; zero when
  // no cascade contains p or the file has no LPV.
  Rgb sample_lpv(const Vec3& p, const Vec3& n) const;
  // Voxel-GI volumes sorted by clipmap_index (finest first); empty when the file has none (1.3).
  const std::vector<VxgiVolume>& vxgi_volumes() const { return vxgi_; }
  // Cone-traced diffuse irradiance (lux) at p for unit normal n from the finest clipmap containing
  // p; false (and zero) when none contains it.
  bool sample_vxgi(const Vec3& p, const Vec3& n, Rgb& out, const ConeOptions& options = {}) const;
  // DDGI irradiance (lux) at p for unit normal n blended over every DDGI volume (docs/FORMAT.md
  // "Several volumes", RTXGI's volume blending): volumes in ddgi_priority() order, each with weight
  // w = DdgiVolume::blend_weight(p), times min(1, sight / GIBAKE_DDGI_FULL_SIGHT) (its probes'
  // sight of p), contributes w x (1 - weight already taken) of its try_sample_irradiance, skipped
  // where it has no answer or w is 0, until the taken weight reaches 1; a sum that ends below 1 (p
  // only in fade bands, or barely seen) is divided by the taken weight. A lone contributor's answer
  // is returned as it is (one volume: exactly sample_irradiance in its region). When none
  // contributes, the first skipped for w = 0 with an answer answers alone, else (on a region face)
  // the first volume holding p.
  // False outside every volume's region; `out` then holds the clamped answer of the nearest volume
  // (by region distance, then priority), what a one-volume sampler without a bounds test gives.
  // With a ddgi_volume_index (1.4) it walks only p's cell's list (the volumes that can weigh in there,
  // in the same order), so the answer is bit-identical to the loop over every volume; outside the
  // index grid, in an empty cell, or where no listed region holds p, it loops over every volume.
  bool sample_ddgi(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& options = {}) const;
  // sample_ddgi without the index: the loop over every volume (what a file without one gets).
  bool sample_ddgi_unindexed(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& options = {}) const;
  // The volumes sample_ddgi takes its answer from at p, with their shares (one volume: share 1).
  // Outside every volume's region, the nearest volume alone, as sample_ddgi answers there.
  std::vector<VolumeShare> ddgi_shares(const Vec3& p, const Vec3& n, const SampleOptions& options = {}) const;
  // The file's volume index (present() false without one).
  const DdgiVolumeIndex& ddgi_index() const { return index_; }
  // Indices into ddgi_volumes(), finest first (DdgiVolume::finest_spacing), ties in file order.
  const std::vector<uint32_t>& ddgi_priority() const { return ddgi_order_; }
  std::string metadata_json() const;  // empty when there is no metadata section
  const uint8_t* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  Error validate(const LoadOptions& options);
  Error validate_sections(const LoadOptions& options);
  Error build_volumes();
  Error validate_layout(const LoadOptions& options) const;
  Error attach(DdgiVolume& volume, uint32_t section_index);
  Error build_lpv();
  Error build_vxgi();
  Error build_ddgi_index();
  void order_ddgi_volumes();
  void build_probe_tiles();
  void reset();

  std::vector<uint8_t> owned_;
  const uint8_t* data_ = nullptr;
  size_t size_ = 0;
  gibake_file_header header_{};
  std::vector<gibake_section_entry> sections_;
  std::vector<DdgiVolume> volumes_;
  std::vector<std::unique_ptr<DdgiVolume::ProbeTiles>> tiles_;  // volumes_[i].tiles_ points into it
  std::vector<uint32_t> ddgi_order_;
  DdgiVolumeIndex index_;
  std::vector<LpvCascade> lpv_;
  std::vector<VxgiVolume> vxgi_;
  int metadata_section_ = -1;
};

}  // namespace gibake::loader
