# Third-party packages of the build: what the libraries link (LibraryDependencies.cmake, shared
# with the installed package config), then what only the tools, tests and benchmarks need.
if(KINOGRAPH_BUILD_TESTS OR KINOGRAPH_BUILD_BENCH)
  find_package(GTest REQUIRED)
  find_package(benchmark REQUIRED)
  find_package(Ceres REQUIRED)     # oracle for the graph engine, tests and benchmarks only
  # KDL: oracle for inverse dynamics, tests only. Its CMake config exports a bare library name.
  find_path(KDL_INCLUDE_DIR kdl/chain.hpp REQUIRED)
  find_library(KDL_LIBRARY orocos-kdl REQUIRED)
  add_library(kdl::kdl UNKNOWN IMPORTED)
  set_target_properties(kdl::kdl PROPERTIES IMPORTED_LOCATION "${KDL_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${KDL_INCLUDE_DIR}")
endif()
# After Ceres: its find module may already have made the SuiteSparse targets.
include(${CMAKE_CURRENT_LIST_DIR}/LibraryDependencies.cmake)
find_package(CLI11 REQUIRED)                                       # the CLI and the daemon
find_program(LCM_GEN lcm-gen REQUIRED)
