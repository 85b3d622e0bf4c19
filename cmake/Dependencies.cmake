# Third-party targets, found the ways that work on Debian 12 (docs/build.md says why).
find_package(PkgConfig REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(urdfdom REQUIRED)
find_package(assimp REQUIRED)
find_package(PNG REQUIRED)
find_package(Freetype REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(CLI11 REQUIRED)
find_package(spdlog REQUIRED)
find_package(Threads REQUIRED)
find_package(EXPAT REQUIRED)                                       # SRDF reading (libexpat1-dev)
pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)                 # needs libglib2.0-dev
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)           # never link libGL too
pkg_check_modules(BULLET64 REQUIRED IMPORTED_TARGET bullet-float64) # carries -DBT_USE_DOUBLE_PRECISION
find_program(LCM_GEN lcm-gen REQUIRED)

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

# Ceres' FindSuiteSparse may already have made this target.
if(NOT TARGET SuiteSparse::CHOLMOD)
  find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
  find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
  find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig REQUIRED)
  add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${SUITESPARSECONFIG_LIBRARY}")
endif()
find_library(CCOLAMD_LIBRARY ccolamd REQUIRED)
find_library(AMD_LIBRARY amd REQUIRED)
