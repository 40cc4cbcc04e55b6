// The bake file writer's throughput (MB/s of file) on a synthetic bake the size of Sponza at
// 64x30x42 = 80,640 probes (about 180 MB: f32 SH, RGBA16F irradiance, RG16F depth moments, as
// GPU bakes write it), split into its parts: building the bytes in memory (encoding, checksums,
// the loader's self-check), the whole atomic write, and the bare write + fsync + rename of the
// same bytes (the floor), also as the writer sends them (4 MiB pieces side by side).
// GIBAKE_BENCH_DIR names the folder written to (default: the temp folder).
//   bench_bake_write --benchmark_min_time=1x
#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>
#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "io/output/bake_atomic.h"
#include "kernels/octahedral.h"
#include "tests/support/ddgi_atlas_sizes.h"

namespace gibake {
namespace {

DdgiResult make_result(int x, int y, int z) {
  DdgiResult r;
  r.desc.counts = {x, y, z};
  r.desc.sh_order = 2;
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = -10.f;
    r.desc.grid_max[a] = 10.f;
    r.desc.spacing[a] = 20.f / float(r.desc.counts[a] - 1);
  }
  r.desc.max_distance = 60.f;
  const size_t n = size_t(r.desc.probe_count());
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> lux(0.f, 30000.f), metres(0.f, 25.f), unit(-1.f, 1.f);
  r.sh.resize(n * 27);
  for (float& v : r.sh) v = lux(rng) * 0.1f;
  r.offsets.resize(n * 3);
  for (float& v : r.offsets) v = unit(rng) * 0.2f;
  r.states.assign(n, ProbeState::Active);
  r.stats.assign(n, DdgiProbeStats{512, 0.01f, 0.5f, 0.f});
  r.atlas_planes_per_row = kernels::atlas_planes_per_row(x, y, kDepthTexels + 2, 16384);
  test::size_ddgi_atlases(r);
  for (size_t i = 0; i < r.irradiance_atlas.size(); ++i) r.irradiance_atlas[i] = i % 4 == 3 ? 1.f : lux(rng);
  for (size_t i = 0; i < r.depth_atlas.size(); i += 2) {
    const float d = metres(rng);
    r.depth_atlas[i] = d;
    r.depth_atlas[i + 1] = d * d * 1.1f;
  }
  r.settings_json = R"({"rays":512,"bounces":4})";
  return r;
}

const DdgiResult& sponza_sized() {
  static const DdgiResult r = make_result(64, 30, 42);
  return r;
}

BakeOutputs outputs_of(const DdgiResult& r) {
  BakeOutputs o;
  o.ddgi = &r;
  o.metadata_json = R"({"tool":"gibake","scene":"synthetic"})";
  o.input_hash = 42;
  return o;
}

std::string out_path() {
  const char* dir = std::getenv("GIBAKE_BENCH_DIR");
  return ((dir ? std::filesystem::path(dir) : std::filesystem::temp_directory_path()) / "bench_bake_write.gibake")
      .string();
}

void set_rate(benchmark::State& state, size_t bytes) {
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(bytes));
  state.counters["MB"] = double(bytes) / 1e6;
}

void BM_BuildBakeFile(benchmark::State& state) {
  const BakeOutputs o = outputs_of(sponza_sized());
  std::vector<uint8_t> bytes;
  for (auto _ : state) {
    if (!build_bake_file(o, BakeFileOptions{}, bytes)) state.SkipWithError("build failed");
    benchmark::DoNotOptimize(bytes.data());
  }
  set_rate(state, bytes.size());
}

void BM_WriteBakeFile(benchmark::State& state) {
  const BakeOutputs o = outputs_of(sponza_sized());
  const std::string path = out_path();
  for (auto _ : state)
    if (!write_bake_file(path, o, BakeFileOptions{}, {})) state.SkipWithError("write failed");
  set_rate(state, std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

// write(2) + fsync + rename of the finished bytes: what any writer pays.
void BM_AtomicWriteOnly(benchmark::State& state) {
  std::vector<uint8_t> bytes;
  if (!build_bake_file(outputs_of(sponza_sized()), BakeFileOptions{}, bytes)) state.SkipWithError("build failed");
  const std::string path = out_path();
  for (auto _ : state)
    if (!write_file_atomic(path, bytes.data(), bytes.size())) state.SkipWithError("write failed");
  set_rate(state, bytes.size());
  std::filesystem::remove(path);
}

// The same bytes as the writer sends them: 4 MiB pieces side by side (AtomicFile::write_at: pwrite,
// then writeback started at once), then fsync and rename. The floor the whole write can reach.
void BM_AtomicWriteInPieces(benchmark::State& state) {
  std::vector<uint8_t> bytes;
  if (!build_bake_file(outputs_of(sponza_sized()), BakeFileOptions{}, bytes)) state.SkipWithError("build failed");
  const std::string path = out_path();
  constexpr size_t kPiece = size_t(4) << 20;
  const size_t pieces = (bytes.size() + kPiece - 1) / kPiece;
  for (auto _ : state) {
    AtomicFile file;
    if (!file.begin(path)) state.SkipWithError("begin failed");
    std::atomic<bool> ok{true};
    tbb::parallel_for(size_t(0), pieces, [&](size_t k) {
      const size_t at = k * kPiece;
      if (!file.write_at(at, bytes.data() + at, std::min(kPiece, bytes.size() - at))) ok = false;
    });
    if (!ok || !file.commit()) state.SkipWithError("write failed");
  }
  set_rate(state, bytes.size());
  std::filesystem::remove(path);
}

// The format's checksum (XXH64) over 64 MB: the loader's own code and libxxhash's.
void BM_Xxh64(benchmark::State& state) {
  std::vector<uint8_t> data(size_t(64) << 20, 0x5a);
  for (auto _ : state)
    benchmark::DoNotOptimize(state.range(0) ? XXH64(data.data(), data.size(), 0) : loader::xxh64(data.data(), data.size(), 0));
  set_rate(state, data.size());
  state.SetLabel(state.range(0) ? "libxxhash" : "loader");
}

BENCHMARK(BM_BuildBakeFile)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WriteBakeFile)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AtomicWriteOnly)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AtomicWriteInPieces)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Xxh64)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace gibake

BENCHMARK_MAIN();
