// Test helper for atomic_test: writes bake files and waits to be killed.
//   atomic_helper hang PATH   begin an atomic write of PATH, write half, print "ready", sleep
//   atomic_helper loop PATH   rewrite PATH with a large bake file forever, "ready" after the first
#include <unistd.h>

#include <cstdio>
#include <string>

#include "io/output/bake_atomic.h"
#include "io/bakefile/bake_file.h"
#include "synthetic.h"

int main(int argc, char** argv) {
  if (argc != 3) return 1;
  const std::string mode = argv[1], path = argv[2];
  const gibake::DdgiResult result = gibake::test::make_ddgi(24, 16, 16, 2, 77);  // ~20 MB in f32
  gibake::BakeOutputs outputs;
  outputs.ddgi = &result;
  gibake::BakeFileOptions options;
  options.atlas = gibake::FloatPrecision::Full;
  if (mode == "hang") {
    std::vector<uint8_t> bytes;
    if (!gibake::build_bake_file(outputs, options, bytes)) return 2;
    gibake::AtomicFile file;
    if (!file.begin(path)) return 3;
    if (!file.write(bytes.data(), bytes.size() / 2)) return 4;
    std::printf("ready %s\n", file.temp_path().c_str());
    std::fflush(stdout);
    for (;;) pause();
  }
  if (mode == "loop") {
    for (int i = 0;; ++i) {
      if (!gibake::write_bake_file(path, outputs, options, {})) return 5;
      if (i == 0) {
        std::printf("ready\n");
        std::fflush(stdout);
      }
    }
  }
  return 1;
}
