// Internal to the loader: the grouping that LPV cascades and voxel-GI volumes share. A descriptor
// section (one descriptor each) starts a group; payload sections name it by its section index in
// their `group` field.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "gibake/loader.hpp"

namespace gibake::loader::groups {

inline Error fail(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

inline std::string label(uint32_t index, const char* type) {
  return "section " + std::to_string(index) + " (" + type + ")";
}

// Every section of `type` read into a Group by `read(index, entry, group)` (which copies and checks
// its descriptor) and appended to `out`, in table order. index_of[i] is the position in `out` of
// section i's group, -1 for sections of other types.
template <class Group, class Read>
Error collect(const std::vector<gibake_section_entry>& sections, uint32_t type, const char* name, Read read,
              std::vector<Group>& out, std::vector<int64_t>& index_of) {
  index_of.assign(sections.size(), -1);
  for (uint32_t i = 0; i < sections.size(); ++i) {
    const gibake_section_entry& s = sections[i];
    if (s.type != type) continue;
    if (s.count != 1) return fail(ErrorCode::BadVolume, label(i, name) + ": count != 1");
    Group g;
    if (Error e = read(i, s, g)) {
      e.message = label(i, name) + ": " + e.message;
      return e;
    }
    index_of[i] = int64_t(out.size());
    out.push_back(std::move(g));
  }
  return {};
}

// The position in the groups of the group payload section i (named `name`) belongs to, or an
// error when its `group` is no descriptor section ("an lpv_cascade section").
inline Error member_of(const std::vector<int64_t>& index_of, const gibake_section_entry& s, uint32_t i,
                       const char* name, const char* descriptor, size_t& at) {
  if (s.group >= index_of.size() || index_of[s.group] < 0)
    return fail(ErrorCode::BadVolume,
                label(i, name) + ": group " + std::to_string(s.group) + " is not " + descriptor + " section");
  at = size_t(index_of[s.group]);
  return {};
}

}  // namespace gibake::loader::groups
