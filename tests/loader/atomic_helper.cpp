// Test helper for atomic_test: writes bake files and waits to be killed.
//   atomic_helper hang PATH   begin an atomic write of PATH, write half, print "ready", sleep
//   atomic_helper loop PATH   rewrite PATH with a large bake file forever, "ready" after the first
//   atomic_helper made DIR    make DIR and write DIR/a.bin as provisional outputs (DIR/kept.bin
//                             kept), begin a write of DIR/b.bin, print "ready", sleep
//   atomic_helper made-all DIR   the same without kept.bin
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "io/bakefile/bake_file.h"
#include "io/output/bake_atomic.h"
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
  if (mode == "made" || mode == "made-all") {  // export's pattern: what the run makes goes with a signal
    gibake::ProvisionalOutputs made, kept;
    made.add_folder(path);
    made.add_file(path + "/a.bin");
    kept.add_file(path + "/kept.bin");
    if (mkdir(path.c_str(), 0755) != 0) return 6;
    if (!gibake::write_bake_file(path + "/a.bin", outputs, options, {})) return 7;
    if (mode == "made" && !gibake::write_bake_file(path + "/kept.bin", outputs, options, {})) return 8;
    kept.keep();
    std::vector<uint8_t> bytes;
    if (!gibake::build_bake_file(outputs, options, bytes)) return 2;
    gibake::AtomicFile file;
    if (!file.begin(path + "/b.bin")) return 3;
    if (!file.write(bytes.data(), bytes.size() / 2)) return 4;
    std::printf("ready\n");
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
