# The third-party libraries kinograph's libraries link, found the ways that work on Debian 12
# (docs/build.md says why). Included by the build and, installed, by kinographConfig.cmake, so
# a downstream project gets the same imported targets the exported ones name.
# In the package config (KINOGRAPH_PACKAGE_CONFIG set) a missing library makes the package
# not found with a message naming the Debian package; in the build it is a fatal error.

# kinograph_dependency_missing(<what> <debian package>): reports a library that is not there.
macro(kinograph_dependency_missing what package)
  set(_kinograph_missing "${what} not found (Debian package ${package})")
  if(KINOGRAPH_PACKAGE_CONFIG)
    set(kinograph_FOUND FALSE)
    set(kinograph_NOT_FOUND_MESSAGE "kinograph needs ${_kinograph_missing}")
    return()
  endif()
  message(FATAL_ERROR "${_kinograph_missing}")
endmacro()

# kinograph_find(<package> <debian package> [find_package arguments...])
macro(kinograph_find package debian)
  if(KINOGRAPH_PACKAGE_CONFIG)
    find_dependency(${package} ${ARGN})
  else()
    find_package(${package} ${ARGN} QUIET)
    if(NOT ${package}_FOUND)
      kinograph_dependency_missing("CMake package ${package}" ${debian})
    endif()
  endif()
endmacro()

# kinograph_pkg(<prefix> <pkg-config module> <debian package>): target PkgConfig::<prefix>.
macro(kinograph_pkg prefix module debian)
  pkg_check_modules(${prefix} QUIET IMPORTED_TARGET ${module})
  if(NOT ${prefix}_FOUND)
    kinograph_dependency_missing("pkg-config module ${module}" ${debian})
  endif()
endmacro()

# kinograph_suitesparse(<component> <header> <library> [library it needs]): our own
# SuiteSparse::<component> target (no CMake config or .pc file is shipped) unless Ceres's
# find module already made one.
macro(kinograph_suitesparse component header library)
  if(NOT TARGET SuiteSparse::${component})
    find_path(KINOGRAPH_${component}_INCLUDE_DIR ${header} PATH_SUFFIXES suitesparse)
    find_library(KINOGRAPH_${component}_LIBRARY ${library})
    if(NOT KINOGRAPH_${component}_INCLUDE_DIR OR NOT KINOGRAPH_${component}_LIBRARY)
      kinograph_dependency_missing("SuiteSparse ${component}" libsuitesparse-dev)
    endif()
    add_library(SuiteSparse::${component} UNKNOWN IMPORTED)
    set_target_properties(SuiteSparse::${component} PROPERTIES
      IMPORTED_LOCATION "${KINOGRAPH_${component}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${KINOGRAPH_${component}_INCLUDE_DIR}")
    foreach(_kinograph_needed ${ARGN})
      find_library(KINOGRAPH_${_kinograph_needed}_LIBRARY ${_kinograph_needed})
      if(NOT KINOGRAPH_${_kinograph_needed}_LIBRARY)
        kinograph_dependency_missing("SuiteSparse ${_kinograph_needed}" libsuitesparse-dev)
      endif()
      set_property(TARGET SuiteSparse::${component} APPEND PROPERTY
        INTERFACE_LINK_LIBRARIES "${KINOGRAPH_${_kinograph_needed}_LIBRARY}")
    endforeach()
  endif()
endmacro()

find_package(PkgConfig QUIET)
if(NOT PkgConfig_FOUND)
  kinograph_dependency_missing("pkg-config" pkg-config)
endif()
kinograph_find(Eigen3 libeigen3-dev 3.3 NO_MODULE)
kinograph_find(urdfdom liburdfdom-dev)
kinograph_find(assimp libassimp-dev)
kinograph_find(PNG libpng-dev)
kinograph_find(nlohmann_json nlohmann-json3-dev)
kinograph_find(yaml-cpp libyaml-cpp-dev)
kinograph_find(spdlog libspdlog-dev)
kinograph_find(Threads libc6-dev)
kinograph_find(EXPAT libexpat1-dev)                               # SRDF reading
kinograph_pkg(LCM lcm "liblcm-dev and libglib2.0-dev")            # lcm.pc requires glib
kinograph_pkg(OSMESA osmesa libosmesa6-dev)                       # never link libGL too
kinograph_pkg(BULLET64 bullet-float64 libbullet-dev)              # carries -DBT_USE_DOUBLE_PRECISION
kinograph_pkg(CAIRO cairo libcairo2-dev)                          # plots and labels
kinograph_suitesparse(CHOLMOD cholmod.h cholmod suitesparseconfig)
kinograph_suitesparse(CCOLAMD ccolamd.h ccolamd)
kinograph_suitesparse(AMD amd.h amd)
