// libFuzzer target: command-line parsing. The input is split at newlines into arguments; they go
// through every shared option parser (numbers, vec3, --sun, on|off, --backend) and through a CLI11
// app with the shared checks (whole numbers, numbers above 0, --threads), as `gibake bake` has them.
#include <cstdint>
#include <string>
#include <vector>

#include "cli/options.h"

using namespace gibake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> args(1);
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') args.emplace_back();
    else args.back() += char(data[i]);
  }
  for (const std::string& a : args) {
    std::vector<double> numbers;
    (void)cli::parse_numbers(a, ',', 3, numbers);
    (void)cli::parse_numbers(a, 'x', 2, numbers);
    std::array<float, 3> v{};
    (void)cli::parse_vec3("--sky", a, v);
    SunLight sun;
    (void)cli::parse_sun(a, sun);
    bool on = false;
    (void)cli::parse_on_off("--relocate", a, on);
    BackendSettings backend;
    (void)cli::parse_backend_options(a, args.size() > 1 ? args[1] : std::string(), backend);
  }
  CLI::App app{"fuzz", "gibake"};
  unsigned threads = 0;
  uint32_t rays = 0;
  float spacing = 0.f;
  std::vector<std::string> suns;
  std::string scene;
  app.add_option("scene", scene);
  cli::add_threads_option(&app, threads, "results");
  app.add_option("--rays", rays)->check(cli::whole_number(1, 1 << 20));
  app.add_option("--probe-spacing", spacing)->check(cli::positive_number());
  app.add_option("--sun", suns);
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
    std::vector<SunLight> parsed;
    (void)cli::parse_suns(suns, parsed);
  } catch (const CLI::Error&) {
  }
  return 0;
}
