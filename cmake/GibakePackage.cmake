# `cmake --install` gives a package: find_package(gibake) provides gibake::loader,
# the imported executable gibake::gibake and the gibake_bake() function.
include(CMakePackageConfigHelpers)

install(TARGETS gibake_loader EXPORT gibakeTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The loader headers and the GLSL sampler engines #include (gibake/ddgi_sample.glsl).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/io/loader/include/gibake
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h" PATTERN "*.hpp" PATTERN "*.glsl")

install(PROGRAMS ${PROJECT_SOURCE_DIR}/scripts/gibake-slurm DESTINATION ${CMAKE_INSTALL_BINDIR})
# The voxel-GI cone tracer for engines' shaders (the twin of the loader's CPU tracer).
install(FILES ${PROJECT_SOURCE_DIR}/kernels/shaders/vxgi_cone.glsl DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/gibake)

set(GIBAKE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/gibake)
install(EXPORT gibakeTargets NAMESPACE gibake:: DESTINATION ${GIBAKE_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/gibakeConfig.cmake.in
  ${PROJECT_BINARY_DIR}/gibakeConfig.cmake INSTALL_DESTINATION ${GIBAKE_CMAKE_DIR}
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/gibakeConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/gibakeConfig.cmake
  ${PROJECT_BINARY_DIR}/gibakeConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/cmake/GibakeBake.cmake
  DESTINATION ${GIBAKE_CMAKE_DIR})
