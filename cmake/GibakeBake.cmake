# gibake_bake(TARGET <name> SCENE <file> OUTPUT <file> [OPTIONS <gibake bake options>...])
#
# Adds a custom command that bakes SCENE into OUTPUT with `gibake bake` and a target <name>
# that builds it. gibake writes a Makefile-style depfile listing the scene and every buffer and
# image it read, so Ninja and Make re-bake only when one of them (or gibake itself) changes.
# OPTIONS default to `--ddgi`.
function(gibake_bake)
  cmake_parse_arguments(GB "" "TARGET;SCENE;OUTPUT" "OPTIONS" ${ARGN})
  foreach(required TARGET SCENE OUTPUT)
    if(NOT GB_${required})
      message(FATAL_ERROR "gibake_bake: ${required} is required")
    endif()
  endforeach()
  if(NOT GB_OPTIONS)
    set(GB_OPTIONS --ddgi)
  endif()
  get_filename_component(scene "${GB_SCENE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(output "${GB_OUTPUT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  get_filename_component(output_dir "${output}" DIRECTORY)
  set(depfile "${CMAKE_CURRENT_BINARY_DIR}/${GB_TARGET}.gibake.d")
  add_custom_command(
    OUTPUT "${output}"
    COMMAND ${CMAKE_COMMAND} -E make_directory "${output_dir}"
    COMMAND gibake::gibake bake "${scene}" ${GB_OPTIONS} --out "${output}" --depfile "${depfile}"
            --progress lines
    DEPENDS "${scene}" gibake::gibake
    DEPFILE "${depfile}"
    COMMENT "gibake: baking ${GB_SCENE}"
    VERBATIM)
  add_custom_target(${GB_TARGET} ALL DEPENDS "${output}")
  set_property(TARGET ${GB_TARGET} PROPERTY GIBAKE_OUTPUT "${output}")
endfunction()
