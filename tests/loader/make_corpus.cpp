// Writes small valid bake files: the fuzz seed corpus / regression corpus (tests/loader/corpus)
// and the docs/FORMAT.md hexdump example.   gibake_make_corpus OUTPUT_DIR
#include <cstdio>
#include <string>

#include "io/bakefile/bake_file.h"
#include "synthetic.h"

namespace {

bool write(const std::string& path, const gibake::DdgiResult& r, bool sh16, bool atlas16, const char* meta,
           const gibake::LpvResult* lpv = nullptr) {
  gibake::BakeOutputs outputs;
  outputs.ddgi = &r;
  outputs.lpv = lpv;
  outputs.metadata_json = meta;
  outputs.input_hash = 0x0123456789abcdefULL;
  gibake::BakeFileOptions options;
  options.sh = sh16 ? gibake::FloatPrecision::Half : gibake::FloatPrecision::Full;
  options.atlas = atlas16 ? gibake::FloatPrecision::Half : gibake::FloatPrecision::Full;
  const gibake::Status s = gibake::write_bake_file(path, outputs, options, {});
  if (!s) std::fprintf(stderr, "%s\n", s.message().c_str());
  return s.is_ok();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 1;
  const std::string dir = argv[1];
  using gibake::test::make_ddgi;
  gibake::DdgiResult example = make_ddgi(2, 1, 1, 1, 1, false);
  example.stats.clear();
  example.settings_json = R"({"rays":64})";
  bool ok = write(dir + "/example_2x1x1_l1.bin", example, false, false, R"({"tool":"gibake"})");
  ok &= write(dir + "/tiny_1x1x1_l1_f16.bin", make_ddgi(1, 1, 1, 1, 2, false), true, true, "{}");
  ok &= write(dir + "/small_2x1x1_l2_atlas16.bin", make_ddgi(2, 1, 1, 2, 3, true), false, true, "{}");
  ok &= write(dir + "/small_1x2x1_l2_f32.bin", make_ddgi(1, 2, 1, 2, 4, true), true, false, R"({"a":[1,2]})");
  gibake::DdgiResult sparse = make_ddgi(5, 1, 2, 1, 7, true);  // probes 4 and 9 inactive: 8 stored
  sparse.sparse = true;
  ok &= write(dir + "/sparse_5x1x2_l1_atlas16.bin", sparse, false, true, "{}");
  const gibake::LpvResult lpv = gibake::test::make_lpv(3, 2, 2, 2, 5);
  ok &= write(dir + "/lpv_2x1x1_l1_3x2x2_2cascades.bin", make_ddgi(2, 1, 1, 1, 6, false), false, false, "{}", &lpv);
  return ok ? 0 : 1;
}
