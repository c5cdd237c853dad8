# Install and export rules: `cmake --install build --prefix PREFIX` puts the libraries, their
# public headers (the generated inscribe/v1/*.pb.h among them), the `inscribe` and `inscribed`
# executables and a CMake package into PREFIX, so that another project can
#   find_package(inscribe CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE inscribe::core inscribe::client)
# The libraries are static: their private dependencies (CGAL, Embree, TBB, OpenSSL, ...) are
# found again by inscribeConfig.cmake. tests/install checks this with a consumer project.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(inscribe_exported core proto wire client robot view viewer_assets build_flags)
foreach(name IN LISTS inscribe_exported)
  set_target_properties(inscribe_${name} PROPERTIES EXPORT_NAME ${name})
endforeach()
list(TRANSFORM inscribe_exported PREPEND inscribe_ OUTPUT_VARIABLE inscribe_exported_targets)
install(TARGETS ${inscribe_exported_targets} EXPORT inscribeTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS inscribe inscribed RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(dir core wire client robot view)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
install(DIRECTORY ${PROJECT_BINARY_DIR}/proto/inscribe DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.pb.h")

set(inscribe_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/inscribe)
install(EXPORT inscribeTargets NAMESPACE inscribe:: DESTINATION ${inscribe_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/inscribeConfig.cmake.in
  ${PROJECT_BINARY_DIR}/inscribeConfig.cmake INSTALL_DESTINATION ${inscribe_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/inscribeConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/inscribeConfig.cmake
              ${PROJECT_BINARY_DIR}/inscribeConfigVersion.cmake
        DESTINATION ${inscribe_cmake_dir})
