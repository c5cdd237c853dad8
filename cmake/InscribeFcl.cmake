# FCL, the exact mesh-mesh distance that tests and benchmarks check and measure against (never
# linked by the libraries). Debian's libfcl-dev (scripts/install-deps), found through its
# fcl-config.cmake, else through pkg-config (whose Cflags carry -std=c++11, hence only its
# paths and libraries). Sets INSCRIBE_FCL_TARGET to the target to link, and defines
# inscribe_fcl_oracle: FCL's trees and the exact distance between posed solids
# (tests/support/fcl_solid_distance.h), for the tests and the benchmarks alike.
find_package(fcl 0.7 CONFIG QUIET)
if(fcl_FOUND)
  set(INSCRIBE_FCL_TARGET fcl)
else()
  find_package(PkgConfig QUIET)
  if(PKG_CONFIG_FOUND)
    pkg_check_modules(INSCRIBE_FCL QUIET fcl>=0.7)
  endif()
  if(NOT INSCRIBE_FCL_FOUND)
    message(FATAL_ERROR "the tests and benchmarks need FCL >= 0.7: install libfcl-dev "
                        "(scripts/install-deps) or configure with -DINSCRIBE_BUILD_TESTS=OFF "
                        "-DINSCRIBE_BUILD_BENCH=OFF")
  endif()
  add_library(inscribe_fcl INTERFACE)
  target_include_directories(inscribe_fcl SYSTEM INTERFACE ${INSCRIBE_FCL_INCLUDE_DIRS})
  target_link_libraries(inscribe_fcl INTERFACE ${INSCRIBE_FCL_LINK_LIBRARIES})
  set(INSCRIBE_FCL_TARGET inscribe_fcl)
endif()

add_library(inscribe_fcl_oracle STATIC ${PROJECT_SOURCE_DIR}/tests/support/fcl_solid_distance.cpp)
target_include_directories(inscribe_fcl_oracle PUBLIC ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(inscribe_fcl_oracle PUBLIC inscribe::core ${INSCRIBE_FCL_TARGET}
  PRIVATE inscribe_build_flags)
