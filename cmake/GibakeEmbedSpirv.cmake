# cmake -DWORDS=in.spv.inc -DHDR=out.h -DNAME=traverse -P GibakeEmbedSpirv.cmake
# Wraps the SPIR-V words glslc wrote as text (`-mfmt=num`: "0x07230203,0x00010300,...") in a C++
# array. No per-word work here: a CMake loop over path.comp's 92k words took minutes of a build.
file(READ ${WORDS} body)
file(WRITE ${HDR} "// Generated from ${NAME}.comp by glslc; do not edit.\n#pragma once\n#include <cstdint>\n"
  "namespace gibake::shaders {\ninline constexpr uint32_t ${NAME}_spv[] = {\n${body}};\n}\n")
