// --backend / --vulkan-device on the bake command and `gibake info --devices`, through the CLI.
// A lavapipe bake is compared with the CPU bake of the same settings by `gibake verify --against`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bake/ddgi/ddgi_memory.h"
#include "gibake/loader.hpp"
#include "tests/vulkan/cli_vk_util.h"

namespace gibake::test {
namespace {

const std::string kSample = cornell_sample_arg();
const std::string kNvpro = shell_quote(std::string(GIBAKE_ASSETS_DIR) + "/cornell-box-nvpro/cornellBox.gltf");

std::string tmp(const std::string& name) { return vk_cli_tmp("gibake_vk_cli_", name); }

bool have_lavapipe() { return have_vk_device(&vk::DeviceInfo::is_lavapipe); }

TEST(BackendCli, ArgumentsAndMissingDevice) {
  const std::string out = tmp("args.gibake");
  const std::string base = kSample + " --ddgi --rays 16 --out " + shell_quote(out);
  EXPECT_EQ(run_gibake_cli(base + " --backend gpu").exit_code, 1);
  EXPECT_EQ(run_gibake_cli(base + " --backend cpu --vulkan-device 0").exit_code, 1);  // needs vulkan|auto (the default)
  const CliResult r = run_gibake_cli(base + " --backend vulkan --vulkan-device no-such-device-anywhere");
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("gibake: error: --backend vulkan: no usable Vulkan device matches"), std::string::npos) << r.err;
  // One error line, the last: the devices are listed while the scene imports and the grid is
  // planned (their progress and notes may come first); a missing one stops the import, or the
  // set-up before it builds anything, and nothing is written.
  size_t error_lines = 0;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);) error_lines += line.rfind("gibake: error: ", 0) == 0;
  EXPECT_EQ(error_lines, 1u) << r.err;
  EXPECT_EQ(r.err.find('\n', r.err.find("gibake: error: ")), r.err.size() - 1) << r.err;  // the last line
  EXPECT_FALSE(std::filesystem::exists(out));
  // auto without a GPU, or with one, always bakes.
  EXPECT_EQ(run_gibake_cli(base + " --backend auto").exit_code, 0);
  std::filesystem::remove(out);
}

TEST(BackendCli, InfoDevices) {
  const CliResult text = run_gibake_cli("info --devices");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("--backend auto uses"), std::string::npos) << text.out;
  const CliResult js = run_gibake_cli("info --devices --format json");
  ASSERT_EQ(js.exit_code, 0) << js.err;
  const auto j = nlohmann::json::parse(js.out);
  ASSERT_TRUE(j.contains("devices"));
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  bool lavapipe = false;
  for (const auto& d : j["devices"]) {
    EXPECT_FALSE(d["name"].get<std::string>().empty());
    lavapipe = lavapipe || d["lavapipe"].get<bool>();
  }
  EXPECT_TRUE(lavapipe);
  EXPECT_NE(text.out.find("lavapipe"), std::string::npos);
  EXPECT_EQ(run_gibake_cli("info --devices " + kSample).exit_code, 1);
  EXPECT_EQ(run_gibake_cli("info").exit_code, 1);
}

// The same bake on lavapipe and the CPU. On Vulkan the relocation rays and the whole path gather
// run on the device (bake/vulkan/path.h) with the CPU's random keys and streams, so paths agree ray for
// ray wherever float rounding does not flip a decision (a hit at a tie between coplanar triangles,
// a roulette or alpha threshold, a mip level), and the atlas texels are f16. Required: verify
// --against passes at 1e-2 lux (statistical agreement, not identity), the ray counts are the same,
// and two lavapipe bakes are the same bytes. `also` runs further checks on the CPU and lavapipe
// files before they are removed.
using BakePairCheck = std::function<void(const std::string& cpu, const std::string& gpu)>;
void compare_with_cpu(const std::string& scene, const std::string& args, const char* name, const std::string& tolerance,
                      const BakePairCheck& also = {}) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const std::string cpu = tmp(std::string(name) + "_cpu.gibake"), gpu = tmp(std::string(name) + "_vk.gibake"),
                    gpu2 = tmp(std::string(name) + "_vk2.gibake");
  const std::string base = scene + " --ddgi " + args + " --out ";
  const CliResult rc = run_gibake_cli(base + shell_quote(cpu) + " --progress lines");
  ASSERT_EQ(rc.exit_code, 0) << rc.err;
  const CliResult r = run_gibake_cli(base + shell_quote(gpu) + " --backend vulkan --vulkan-device lavapipe --progress lines");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("backend vulkan: llvmpipe"), std::string::npos) << r.err;
  const auto rays_line = [](const std::string& err) { return err.substr(err.find("  rays: "), 60); };
  EXPECT_EQ(rays_line(r.err).substr(0, 50), rays_line(rc.err).substr(0, 50));
  ASSERT_EQ(run_gibake_cli(base + shell_quote(gpu2) + " --backend vulkan --vulkan-device lavapipe").exit_code, 0);
  EXPECT_EQ(read_text_file(gpu), read_text_file(gpu2));  // deterministic on one device
  const CliResult v = run_gibake_cli("verify " + shell_quote(gpu) + " --against " + shell_quote(cpu) +
                                     " --tolerance " + tolerance + " --format json");
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  // The file says where it ran; a CPU bake's settings stay as they were (no backend key).
  const CliResult gi = run_gibake_cli("info " + shell_quote(gpu) + " --format json");
  EXPECT_NE(gi.out.find("\"backend\": \"vulkan\""), std::string::npos);
  EXPECT_NE(gi.out.find("\"vulkan_device\": \"llvmpipe"), std::string::npos);
  const CliResult ci = run_gibake_cli("info " + shell_quote(cpu) + " --format json");
  EXPECT_EQ(ci.out.find("\"backend\""), std::string::npos);
  if (also) also(cpu, gpu);
  for (const auto& f : {cpu, gpu, gpu2}) std::filesystem::remove(f);
}

// A 4x4x4 grid of the sample (the probe gather's bounce test below too): every probe runs every kernel
// of the bake (relocation, adaptive passes, bounces, integration) at a ninth of the default grid's cost.
TEST(BackendCli, LavapipeBakeMatchesCpuOnSample) {
  compare_with_cpu(kSample, "--rays 64 --bounces 2 --probe-counts 4,4,4", "sample", "0.01");
}

TEST(BackendCli, LavapipeProbeFeedbackMatchesCpu) {
  compare_with_cpu(kSample, "--rays 64 --bounces 2 --gather probes --probe-counts 4,4,4", "probes", "0.01");
}

// --gather probes with the default adaptive rays and 4 bounce passes: the passes run on the device
// (bake/vulkan/bounce.h) and say so in the notes. The device's passes round as the trace pass does,
// and atlas texels are f16, so the bake must match the CPU bake within verify's 1e-2 lux and give
// the same bytes twice. A 4x4x4 grid keeps lavapipe's three bakes short; every probe still runs
// every pass.
TEST(BackendCli, LavapipeProbeFeedbackBouncesOnDevice) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const std::string cpu = tmp("bounce_cpu.gibake"), gpu = tmp("bounce_vk.gibake"), gpu2 = tmp("bounce_vk2.gibake");
  const std::string base = kSample + " --ddgi --gather probes --probe-counts 4,4,4 --out ";
  const std::string vk = " --backend vulkan --vulkan-device lavapipe";
  ASSERT_EQ(run_gibake_cli(base + shell_quote(cpu)).exit_code, 0);
  const CliResult r = run_gibake_cli(base + shell_quote(gpu) + vk + " --progress lines");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("vulkan: bounce kernels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bounces (vulkan)"), std::string::npos) << r.err;
  // The default adaptive rays keep every ray's hit on the host for the bounce passes: said, not silent.
  EXPECT_NE(r.err.find("per-ray records on the host between passes (kernels still trace and integrate on the "
                       "device): --gather probes keeps each ray's hit for the bounce passes"),
            std::string::npos)
      << r.err;
  ASSERT_EQ(run_gibake_cli(base + shell_quote(gpu2) + vk).exit_code, 0);
  EXPECT_EQ(read_text_file(gpu), read_text_file(gpu2));
  const CliResult v = run_gibake_cli("verify " + shell_quote(gpu) + " --against " + shell_quote(cpu) + " --tolerance 0.01");
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  for (const auto& f : {cpu, gpu, gpu2}) std::filesystem::remove(f);
}

// --cache-dir: the first Vulkan bake builds the BVH and stores it, the second loads it (and says
// so), and both files are the bytes of a bake with the cache off. A 4x4x4 grid: the tree is the
// scene's whatever the grid, and every ray of the bake (relocation, paths, the reconstruction check's
// reference paths) walks it.
TEST(BackendCli, BvhCacheGivesTheSameBytes) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const std::string cache = tmp("bvh_cache_dir"), off = tmp("cache_off.gibake"), cold = tmp("cache_cold.gibake"),
                    warm = tmp("cache_warm.gibake");
  std::filesystem::remove_all(cache);
  const std::string base =
      kSample + " --ddgi --probe-counts 4,4,4 --rays 32 --bounces 1 --backend vulkan --vulkan-device lavapipe "
                "--progress lines";
  const CliResult r_off = run_gibake_cli(base + " --cache-dir off --out " + shell_quote(off));
  ASSERT_EQ(r_off.exit_code, 0) << r_off.err;
  EXPECT_NE(r_off.err.find(", BVH build "), std::string::npos) << r_off.err;
  const CliResult r_cold = run_gibake_cli(base + " --cache-dir " + shell_quote(cache) + " --out " + shell_quote(cold));
  ASSERT_EQ(r_cold.exit_code, 0) << r_cold.err;
  EXPECT_NE(r_cold.err.find("BVH build (cached)"), std::string::npos) << r_cold.err;
  const CliResult r_warm = run_gibake_cli(base + " --cache-dir " + shell_quote(cache) + " --out " + shell_quote(warm));
  ASSERT_EQ(r_warm.exit_code, 0) << r_warm.err;
  EXPECT_NE(r_warm.err.find("BVH from the cache"), std::string::npos) << r_warm.err;
  EXPECT_EQ(read_text_file(off), read_text_file(cold));
  EXPECT_EQ(read_text_file(off), read_text_file(warm));
  size_t entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(cache)) entries += e.path().extension() == ".gbvh";
  EXPECT_EQ(entries, 1u);
  std::filesystem::remove_all(cache);
  for (const auto& f : {off, cold, warm}) std::filesystem::remove(f);
}

// Where the cache goes without --cache-dir: $GIBAKE_CACHE_DIR, else $XDG_CACHE_HOME/gibake (the
// tests' own environment says GIBAKE_CACHE_DIR=off, restored after).
TEST(BackendCli, BvhCacheFolderFollowsTheEnvironment) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const char* was = std::getenv("GIBAKE_CACHE_DIR");
  const std::string saved = was ? was : "";
  const std::string xdg = tmp("xdg_cache"), named = tmp("named_cache"), out = tmp("cache_env.gibake");
  std::filesystem::remove_all(xdg);
  std::filesystem::remove_all(named);
  const auto entries = [](const std::string& dir) {
    size_t n = 0;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) n += e.path().extension() == ".gbvh";
    return n;
  };
  // The checks after the trace (reconstruction paths, leak audit) would only add to its time: the
  // tree is stored when it is built, before the first ray.
  const std::string bake = kSample +
                           " --ddgi --probe-counts 4,4,4 --rays 16 --target-error 0 --bounces 1 --backend vulkan "
                           "--vulkan-device lavapipe --reconstruction-check off --leak-audit off --out " +
                           shell_quote(out);
  // Mesa keeps lavapipe's compiled kernels under the XDG cache too: pointed at the usual folder, so
  // that moving XDG_CACHE_HOME does not cost a cold compile (tens of seconds).
  const char* xdg_was = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  const std::string mesa = xdg_was ? std::string(xdg_was) + "/mesa_shader_cache"
                                   : std::string(home ? home : "/tmp") + "/.cache/mesa_shader_cache";
  const bool mesa_set = std::getenv("MESA_SHADER_CACHE_DIR") != nullptr;
  if (!mesa_set) ::setenv("MESA_SHADER_CACHE_DIR", mesa.c_str(), 1);
  const std::string xdg_saved = xdg_was ? xdg_was : "";
  ::unsetenv("GIBAKE_CACHE_DIR");
  ::setenv("XDG_CACHE_HOME", xdg.c_str(), 1);
  const CliResult by_xdg = run_gibake_cli(bake);
  ::setenv("GIBAKE_CACHE_DIR", named.c_str(), 1);
  const CliResult by_name = run_gibake_cli(bake);
  if (!xdg_saved.empty())
    ::setenv("XDG_CACHE_HOME", xdg_saved.c_str(), 1);
  else
    ::unsetenv("XDG_CACHE_HOME");
  if (!mesa_set) ::unsetenv("MESA_SHADER_CACHE_DIR");
  if (was)
    ::setenv("GIBAKE_CACHE_DIR", saved.c_str(), 1);
  else
    ::unsetenv("GIBAKE_CACHE_DIR");
  ASSERT_EQ(by_xdg.exit_code, 0) << by_xdg.err;
  ASSERT_EQ(by_name.exit_code, 0) << by_name.err;
  EXPECT_EQ(entries(xdg + "/gibake"), 1u);
  EXPECT_EQ(entries(named), 1u);  // not the XDG folder's: it built and stored its own
  EXPECT_EQ(entries(xdg + "/gibake"), 1u);
  for (const auto& d : {xdg, named}) std::filesystem::remove_all(d);
  std::filesystem::remove(out);
}

TEST(BackendCli, LavapipeBakeMatchesCpuOnCornellNvpro) {
  compare_with_cpu(kNvpro, "--rays 32 --bounces 1 --probe-counts 6,6,6", "nvpro", "0.01");
}

// --target-error through the CLI on lavapipe (statistics and integrals stay on the device between
// passes, bake/vulkan/ddgi_device.cpp): verify --against the CPU bake at 1e-2 lux (compare_with_cpu,
// the same bytes twice too), and the files' per-probe ray counts equal: the same stop decisions.
TEST(BackendCli, LavapipeAdaptiveBakeMatchesCpuPerProbe) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const std::string args = "--rays 32 --target-error 0.05 --max-rays 512 --bounces 2 --probe-counts 4,4,4";
  compare_with_cpu(kSample, args, "adaptive", "0.01", [](const std::string& cpu, const std::string& gpu) {
    loader::BakeFile a, b;
    ASSERT_TRUE(a.open(cpu).ok());
    ASSERT_TRUE(b.open(gpu).ok());
    const loader::DdgiVolume& va = a.ddgi_volumes().at(0);
    const loader::DdgiVolume& vb = b.ddgi_volumes().at(0);
    ASSERT_TRUE(va.has_stats() && vb.has_stats());
    ASSERT_EQ(va.probe_count(), vb.probe_count());
    uint32_t lo = ~0u, hi = 0;
    for (uint32_t p = 0; p < va.probe_count(); ++p) {
      EXPECT_EQ(vb.stats(p).rays, va.stats(p).rays) << "probe " << p;
      lo = std::min(lo, va.stats(p).rays);
      hi = std::max(hi, va.stats(p).rays);
    }
    EXPECT_LT(lo, hi) << "the probes should stop after different passes";
  });
}

}  // namespace

namespace {
// A CPU device does not trace the fit's paths (make_gpu_reference_paths): the host keeps their first
// hits for the fit's second pass and reads the probes through its tables, as on the CPU route. So a
// lavapipe bake's estimate is the CPU route's plus the device's staging, which only Vulkan holds;
// leaving the fit's host work out would make it smaller by the kept hits and tables.
TEST(BackendCli, LavapipeBakeCountsTheFitsHostWork) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const std::string base =
      kSample +
      " --ddgi --rays 16 --target-error 0 --refine-budget 0 --reconstruction-check off --probe-counts 4,4,4"
      " --fit-passes 2 --progress lines --out ";
  const CliResult cpu = run_gibake_cli(base + shell_quote(tmp("fitmem_cpu.gibake")) + " --backend cpu");
  ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
  const CliResult gpu =
      run_gibake_cli(base + shell_quote(tmp("fitmem_vk.gibake")) + " --backend vulkan --vulkan-device lavapipe");
  ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
  const long cpu_mib = noted_memory_mib(cpu), gpu_mib = noted_memory_mib(gpu);
  ASSERT_GT(cpu_mib, 0) << cpu.err;
  ASSERT_GT(gpu_mib, 0) << gpu.err;
  DdgiMemoryShape staging;  // an empty bake on a device: the staging alone
  staging.vulkan = true;
  const long staging_mib = long(estimate_ddgi_memory(staging).total() >> 20);
  EXPECT_NEAR(double(gpu_mib - cpu_mib), double(staging_mib), 1.0) << cpu.err << gpu.err;
  std::filesystem::remove(tmp("fitmem_cpu.gibake"));
  std::filesystem::remove(tmp("fitmem_vk.gibake"));
}

// --lpv on Vulkan: the propagation runs on the device; verify --against the CPU bake at 1e-4 lux.
TEST(BackendCli, LavapipeLpvMatchesCpu) {
  if (!have_lavapipe()) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  const std::string cpu = tmp("lpv_cpu.gibake"), gpu = tmp("lpv_vk.gibake");
  const std::string base = kSample + " --lpv --lpv-res 16 --out ";
  ASSERT_EQ(run_gibake_cli(base + shell_quote(cpu)).exit_code, 0);
  const CliResult r = run_gibake_cli(base + shell_quote(gpu) + " --backend vulkan --vulkan-device lavapipe");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CliResult v = run_gibake_cli("verify " + shell_quote(gpu) + " --against " + shell_quote(cpu) + " --tolerance 0.0001");
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  EXPECT_NE(v.out.find("against.lpv[0]"), std::string::npos) << v.out;
  EXPECT_NE(run_gibake_cli("info " + shell_quote(gpu) + " --format json").out.find("\"vulkan_device\""), std::string::npos);
  std::filesystem::remove(cpu);
  std::filesystem::remove(gpu);
}
}  // namespace
}  // namespace gibake::test
