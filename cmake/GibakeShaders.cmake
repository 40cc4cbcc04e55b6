# gibake_shaders(<target> <header-dir> SOURCES a.comp b.comp ...): compiles each GLSL compute
# shader with glslc at build time and turns its SPIR-V into a header `<name>_spv.h` holding
# `constexpr uint32_t k<Name>Spv[]`, so the binary carries its kernels (no files at run time).
# Includes resolve against kernels/shaders and io/loader/include (the GLSL sampler engines get).
find_program(GIBAKE_GLSLC glslc REQUIRED)

function(gibake_shaders target header_dir)
  cmake_parse_arguments(S "" "" "SOURCES;DEPENDS" ${ARGN})
  set(headers)
  foreach(src ${S_SOURCES})
    get_filename_component(name ${src} NAME_WE)
    set(words ${header_dir}/${name}.spv.inc)
    set(hdr ${header_dir}/${name}_spv.h)
    add_custom_command(
      OUTPUT ${hdr}
      COMMAND ${GIBAKE_GLSLC} --target-env=vulkan1.1 -O -Werror -I ${PROJECT_SOURCE_DIR}/kernels/shaders
              -I ${PROJECT_SOURCE_DIR}/io/loader/include
              -mfmt=num -o ${words} ${src}
      COMMAND ${CMAKE_COMMAND} -DWORDS=${words} -DHDR=${hdr} -DNAME=${name}
              -P ${PROJECT_SOURCE_DIR}/cmake/GibakeEmbedSpirv.cmake
      DEPENDS ${src} ${S_DEPENDS} ${PROJECT_SOURCE_DIR}/cmake/GibakeEmbedSpirv.cmake
      COMMENT "glslc ${name}.comp"
      VERBATIM)
    list(APPEND headers ${hdr})
  endforeach()
  add_custom_target(${target} DEPENDS ${headers})
endfunction()
