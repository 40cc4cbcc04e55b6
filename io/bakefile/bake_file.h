// Writing .gibake bake files (format: io/loader/include/gibake/format.h, docs/FORMAT.md).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gibake/format.h"
#include "io/results/ddgi_result.h"
#include "io/results/lpv_result.h"
#include "io/results/vxgi_result.h"
#include "io/status.h"

struct XXH3_state_s;

namespace gibake {

class BakeFileStream;

// Storage precision of a float section.
enum class FloatPrecision : uint8_t {
  Auto = 0,  // float16 when every value fits its range (|v| <= 65504), else float32
  Half = 1,  // float16, clamping larger values to 65504 (reported through `warn`)
  Full = 2,  // float32
  // Atlases only: the irradiance atlas as RGB9E5 (4 bytes a texel, format 1.5) when every value fits
  // (0 to 65408 lux), else as Auto; the depth atlas as Auto.
  SharedExponent = 3,
};

struct BakeFileOptions {
  FloatPrecision sh = FloatPrecision::Full;      // SH coefficients (DDGI probes and LPV cells)
  // Atlases as RGBA16F / RG16F when they fit: sunlight reaches 100000 lux and depth moments
  // (m^2) pass 65504 beyond ~255 m, so Auto keeps such atlases in 32-bit.
  FloatPrecision atlas = FloatPrecision::Auto;
  FloatPrecision vxgi = FloatPrecision::Auto;    // voxel-GI radiance (RGBA16F when it fits)
  // Optional: told when float16 conversion clamps values above 65504.
  std::function<void(const std::string&)> warn;
  // Threads for converting large payloads (the same bytes for any count); 0: all hardware threads.
  unsigned threads = 0;
  // Optional: told the seconds of the write's parts ("encoded and written", "committed").
  std::function<void(const char* part, double seconds)> timing;
  // Every DDGI volume in its grid's layout, whatever DdgiResult::sparse asks: for a file whose
  // atlases must line up with the results' (the surface fit reads its texels back into them).
  bool dense_volumes = false;
  // Optional (write_bake_file only): the file begun during the bake, its first DDGI volume's atlases
  // written as they became final (bake_stream.h); adopted when the outputs lay out as it predicted.
  BakeFileStream* stream = nullptr;
};

// A section written as given: bake intermediates (shard files) and sections the merge copies from a
// shard (LPV). `group` is an index into BakeOutputs::extra (the writer turns it into a table index).
struct RawSection {
  uint32_t type = 0, format = 0, group = 0;
  uint64_t count = 0;
  std::vector<uint8_t> bytes;
};

struct BakeOutputs {
  const DdgiResult* ddgi = nullptr;  // optional section group
  // More DDGI volumes (bake/ddgi/volumes.h), each its own section group after `ddgi`, in order.
  std::vector<const DdgiResult*> ddgi_more;
  const LpvResult* lpv = nullptr;    // optional: one lpv_cascade + lpv_sh pair per cascade (1.2)
  const VxgiResult* vxgi = nullptr;  // optional: vxgi_volume + vxgi_radiance (+ vxgi_sdf) per clipmap (1.3)
  std::string metadata_json;          // settings, tool version, timings
  uint64_t input_hash = 0;            // hash_inputs() of the scene files and settings
  const std::vector<RawSection>* extra = nullptr;  // optional: after DDGI and LPV, before the metadata
};

// Hash of the scene files' bytes (scene, buffers, images), the bake settings and the gibake
// version, for staleness checks. XXH3-64. `settings` is canonicalised first when it parses as JSON
// (keys sorted, compact), so the bake command and `gibake verify --scene` (which re-hashes the
// metadata's "settings" object) agree however the JSON was spaced.
Status hash_inputs(const std::vector<std::string>& files, const std::string& settings,
                   uint64_t& out);

// hash_inputs in two steps: the files (megabytes of scene, buffers and images, known after the
// import) hashed beside the bake, the settings (known at its end) added after. The same value.
class InputHash {
 public:
  InputHash();
  Status add_files(const std::vector<std::string>& files);
  // The settings and gibake's version after the files; the files' part is kept (finish again).
  Status finish(const std::string& settings, uint64_t& out) const;

 private:
  // xxHash's streaming state (xxhash.h stays out of this header).
  std::unique_ptr<::XXH3_state_s, void (*)(::XXH3_state_s*)> state_;
};

// Atomic write: temporary file in the target folder, fsync, rename, fsync folder. Refuses to
// overwrite any of `inputs` (same device and inode). The previous file survives any failure.
Status write_bake_file(const std::string& path, const BakeOutputs& outputs,
                       const BakeFileOptions& options, const std::vector<std::string>& inputs);

// write_bake_file that also hands the finished file's bytes (exactly what is committed) to
// `while_committing`, run on the calling thread while another commits the file (fsync, rename):
// readers of the new file (the reconstruction check) then neither wait for the disk nor read the
// file back. The bytes are valid only during the call. When the commit fails its error is
// returned, whatever the callback returned; else the callback's status.
using BytesReader = std::function<Status(const uint8_t* data, size_t size)>;
Status write_bake_file(const std::string& path, const BakeOutputs& outputs, const BakeFileOptions& options,
                       const std::vector<std::string>& inputs, const BytesReader& while_committing);

// The bytes write_bake_file would write (no file I/O); for tests, fuzz corpora and tools.
Status build_bake_file(const BakeOutputs& outputs, const BakeFileOptions& options,
                       std::vector<uint8_t>& out);

// The gibake version baked into hashes and metadata.
const char* gibake_version_string();

// A DDGI volume's record as bake files and shard infos hold it, but for the atlas sizes (left 0):
// the grid, its SH order and coefficient count, the units and the tile sizes.
gibake_ddgi_volume ddgi_volume_record(const DdgiVolumeDesc& desc);

}  // namespace gibake
