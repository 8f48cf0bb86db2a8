# Installs the library, its headers and a CMake package, so that another project can
# `find_package(clothcd)` and link `clothcd::clothcd`.
include(CMakePackageConfigHelpers)

install(TARGETS clothcd EXPORT clothcdTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/clothcd DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT clothcdTargets NAMESPACE clothcd:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clothcd)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/clothcdConfig.cmake.in
  ${PROJECT_BINARY_DIR}/clothcdConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clothcd)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/clothcdConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/clothcdConfig.cmake ${PROJECT_BINARY_DIR}/clothcdConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/clothcd)
