# gibake_bake(TARGET <name> SCENE <file> OUTPUT <file> [OPTIONS <gibake bake options>...])
#
# Adds a custom command that bakes SCENE into OUTPUT with `gibake bake` and a target <name>
# that builds it. gibake writes a Makefile-style depfile listing the scene and every buffer and
# image it read, so Ninja and Make re-bake only when one of them (or gibake itself) changes.
# OPTIONS default to `--ddgi`.
#
# SLURM_SHARDS <N> [SLURM_ARGS <gibake-slurm options>...]: bake through Slurm instead, as N shards
# (a job array) plus a dependent merge job, waiting for the merge (bin/gibake-slurm --wait; the build
# host must be a submit host and the cluster's nodes must see the same paths, gibake included). The
# output is byte-identical to the local bake. SLURM_ARGS e.g. --partition gpu --gpus-per-shard 1
# --sbatch-arg --time=2:00:00.
function(gibake_bake)
  cmake_parse_arguments(GB "" "TARGET;SCENE;OUTPUT;SLURM_SHARDS" "OPTIONS;SLURM_ARGS" ${ARGN})
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
  set(bake_command gibake::gibake bake "${scene}" ${GB_OPTIONS} --out "${output}" --depfile "${depfile}"
      --progress lines)
  if(GB_SLURM_SHARDS)
    if(NOT GIBAKE_SLURM_SCRIPT OR NOT EXISTS "${GIBAKE_SLURM_SCRIPT}")
      find_program(GIBAKE_SLURM_SCRIPT gibake-slurm REQUIRED)
    endif()
    set(bake_command "${GIBAKE_SLURM_SCRIPT}" "${scene}" ${GB_OPTIONS} --out "${output}" --depfile "${depfile}"
        --shards ${GB_SLURM_SHARDS} --gibake $<TARGET_FILE:gibake::gibake> --wait ${GB_SLURM_ARGS})
  endif()
  add_custom_command(
    OUTPUT "${output}"
    COMMAND ${CMAKE_COMMAND} -E make_directory "${output_dir}"
    COMMAND ${bake_command}
    DEPENDS "${scene}" gibake::gibake
    DEPFILE "${depfile}"
    COMMENT "gibake: baking ${GB_SCENE}"
    VERBATIM)
  add_custom_target(${GB_TARGET} ALL DEPENDS "${output}")
  set_property(TARGET ${GB_TARGET} PROPERTY GIBAKE_OUTPUT "${output}")
endfunction()
