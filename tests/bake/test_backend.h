// The backend the bake tests run on: the CPU; their Vulkan twins (tests/vulkan/CMakeLists.txt,
// built with GIBAKE_TEST_VULKAN) run the very same tests on lavapipe, and skip all of them, saying
// why, when no Vulkan device opens.
#pragma once
#include "bake/ddgi/ddgi.h"

namespace gibake::test {

inline DdgiSettings on_test_backend(DdgiSettings s) {
#ifdef GIBAKE_TEST_VULKAN
  s.backend.backend = Backend::Vulkan;
  s.backend.vulkan_device = "lavapipe";
#endif
  return s;
}

}  // namespace gibake::test
