// Bake files with several DDGI volumes for loader, preview and GLSL tests, written with the
// one-volume writer: the first volume as BakeOutputs::ddgi, every other one's sections (as the
// writer encodes them for a file of its own) appended through BakeOutputs::extra, their `group`
// pointing at their own ddgi_volume section.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "io/results/ddgi_result.h"
#include "io/status.h"

namespace gibake::test {

inline Status multi_volume_bytes(const std::vector<const DdgiResult*>& volumes, const BakeFileOptions& options,
                                 std::vector<uint8_t>& out, const std::string& metadata_json = "") {
  if (volumes.empty()) return Status::error(ExitCode::BadArguments, "", "volumes", "none given");
  std::vector<RawSection> extra;
  for (size_t v = 1; v < volumes.size(); ++v) {
    BakeOutputs one;
    one.ddgi = volumes[v];
    std::vector<uint8_t> bytes;
    GIBAKE_TRY(build_bake_file(one, options, bytes));
    loader::BakeFile file;
    if (file.open_borrowed(bytes.data(), bytes.size()))
      return Status::error(ExitCode::BadArguments, "", "volume", "the one-volume file does not load");
    const uint32_t group = uint32_t(extra.size());
    for (size_t i = 0; i < file.sections().size(); ++i) {
      const gibake_section_entry& s = file.sections()[i];
      const bool ddgi = (s.type >= GIBAKE_SECTION_DDGI_VOLUME && s.type <= GIBAKE_SECTION_DDGI_DEPTH) ||
                        s.type == GIBAKE_SECTION_DDGI_PROBE_SLOTS;
      if (!ddgi) continue;
      RawSection r;
      r.type = s.type;
      r.format = s.format;
      r.group = group;
      r.count = s.count;
      const uint8_t* data = file.section_data(uint32_t(i));
      r.bytes.assign(data, data + s.size);
      extra.push_back(std::move(r));
    }
  }
  BakeOutputs outputs;
  outputs.ddgi = volumes[0];
  outputs.extra = &extra;
  outputs.metadata_json = metadata_json;
  return build_bake_file(outputs, options, out);
}

}  // namespace gibake::test
