// Probe fields for paths that end in the probes' light: a bake file's (BakeFileProbeField), and any
// field read through a table of each thread's (CachedProbeField). Paths ended in the
// probes' light at their first hit land again and again on the same patches of surface, and the
// probes' light there changes over the probes' spacing, not over the few centimetres between hits:
// one read serves every hit on a patch that faces the same way.
//
// A read is keyed by where the hit lies (a cube of `cell` metres and, within it, the plane through
// the hit, to an eighth of the cell) and the way it faces (one of 32 x 32 octahedral bins of the
// normal). The field is read at the key's own point and normal: the cube's centre moved onto the
// key's plane along the bin's central normal, which lies within the cell's diagonal of every hit
// with that key. A value is therefore a function of its key alone: what a path reads depends on
// neither the thread nor the reads before it, and a bake's bytes stay the same for any thread count.
// The tables are direct-mapped; a read whose slot holds another key reads the field and takes the
// slot.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

#include "bake/trace/path_gather.h"

namespace gibake {

// The probes of a bake file as a field: every DDGI volume blended by the runtime sampler
// (loader::BakeFile::sample_ddgi) with its default options, as an engine reads them.
class BakeFileProbeField final : public ProbeField {
 public:
  explicit BakeFileProbeField(const loader::BakeFile& file) : file_(file) {}  // must outlive this
  kernels::float3 irradiance(const kernels::float3& p, const kernels::float3& n) const override;
  const loader::BakeFile* file() const override { return &file_; }

 private:
  const loader::BakeFile& file_;
};

class CachedProbeField final : public ProbeField {
 public:
  struct Key {
    int32_t cell[3] = {0, 0, 0};  // floor(p / cell)
    int32_t plane = 0;            // floor(dot(p, normal) / (cell / 8))
    int32_t normal = -1;          // octahedral bin, row by row; -1: an empty slot
    bool operator==(const Key& o) const {
      return cell[0] == o.cell[0] && cell[1] == o.cell[1] && cell[2] == o.cell[2] && plane == o.plane &&
             normal == o.normal;
    }
  };

  static constexpr int kNormalBins = 32;  // a side of the octahedral square; about 6 degrees a bin
  static constexpr int kPlaneSteps = 8;   // plane offsets a cell

  // `cell`: the cubes' side in metres, > 0 and finite. Each thread's table holds 2^table_bits
  // reads. `field` must outlive this.
  CachedProbeField(const ProbeField& field, float cell, int table_bits);

  // The tables' size for `threads` threads: a million reads each, fewer where the threads are many,
  // so that all of them together stay within 256 MiB. A table finds a read again only while it still
  // holds the reads of the points around it, a few thousand points' hits (docs/BENCHMARKS.md "The
  // fit's probe reads shared per cube").
  static int table_bits_for(uint32_t threads);
  // Bytes of one thread's table of 2^bits reads.
  static uint64_t table_bytes(int bits);

  kernels::float3 irradiance(const kernels::float3& p, const kernels::float3& n) const override;
  // The file the field reads. A device that reads it itself reads it at every hit, not per key.
  const loader::BakeFile* file() const override { return field_.file(); }

  // Whether any thread has read through the tables (false where a device read the probes itself).
  bool used() const;

  // The key of a read at p with normal n, and the point and normal at which the field is read for it.
  Key key_of(const kernels::float3& p, const kernels::float3& n) const;
  void read_at(const Key& k, kernels::float3& p, kernels::float3& n) const;

 private:
  struct Slot {
    Key key;
    kernels::float3 value{};
  };
  const ProbeField& field_;
  float cell_;
  int table_bits_;
  mutable tbb::enumerable_thread_specific<std::vector<Slot>> tables_;
};

}  // namespace gibake
