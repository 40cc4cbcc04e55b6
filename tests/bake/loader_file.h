// A bake's DDGI result as an engine reads it: written to bytes as the CLI writes a file (the
// settings in its metadata), then opened with the loader.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "io/results/ddgi_result.h"

namespace gibake::test {

inline void open_in_loader(const DdgiResult& result, loader::BakeFile& file) {
  BakeOutputs out;
  out.ddgi = &result;
  out.metadata_json = "{\"settings\":" + result.settings_json + "}";
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(build_bake_file(out, BakeFileOptions{}, bytes).is_ok());
  ASSERT_FALSE(file.open(std::move(bytes)));
}

}  // namespace gibake::test
