# Installs the library, its headers and a CMake package, so that another project can
# `find_package(clothcd)` and link `clothcd::clothcd`.
include(CMakePackageConfigHelpers)

install(TARGETS clothcd EXPORT clothcdTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# Headers of code that is not installed (the experiment harness, linked into the CLI only) or
# that serves the CLI, benchmarks and tests rather than users (CCD query files, procedural
# scenes, frame rendering, the viewer page) stay out of the install.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/clothcd DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  PATTERN experiment EXCLUDE
  PATTERN query_csv.hpp EXCLUDE
  PATTERN procedural.hpp EXCLUDE
  PATTERN render.hpp EXCLUDE
  PATTERN view EXCLUDE)
install(EXPORT clothcdTargets NAMESPACE clothcd:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clothcd)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/clothcdConfig.cmake.in
  ${PROJECT_BINARY_DIR}/clothcdConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clothcd)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/clothcdConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/clothcdConfig.cmake ${PROJECT_BINARY_DIR}/clothcdConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clothcd)
