# Install layout and the exported CMake package `kinograph` (find_package(kinograph 0.1)):
#   bin/kinograph, bin/kinographd                     the CLI and the daemon
#   lib/libkinograph_<module>.a                        one library per module
#   include/kinograph/{kinograph,render,daemon,lcmtypes}/   headers, include root include/kinograph
#   share/kinograph/robots, share/kinograph/lcmtypes  robots, scenes, LCM definitions
#   lib/cmake/kinograph/                               kinographConfig.cmake and the targets
# Headers sit below include/kinograph so that their own include paths ("render/image.h") do not
# claim top-level names in the prefix.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(KINOGRAPH_INSTALL_INCLUDEDIR ${CMAKE_INSTALL_INCLUDEDIR}/kinograph)
set(KINOGRAPH_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/kinograph)
set(KINOGRAPH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/kinograph)

# kinograph_export_module(<target> <name>): installs a module library as kinograph::<name>
# (and makes that alias in the build, so in-tree and downstream code name it the same).
function(kinograph_export_module target name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  add_library(kinograph::${name} ALIAS ${target})
  install(TARGETS ${target} EXPORT kinographTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    INCLUDES DESTINATION ${KINOGRAPH_INSTALL_INCLUDEDIR})
  set_property(GLOBAL APPEND PROPERTY KINOGRAPH_MODULES ${target})
endfunction()

# The build tree's data directory: build/share/kinograph/robots links to the sources, so the
# CLI and daemon in build/ find shipped robots as the installed ones do (planning/io/data_dir.h).
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/${CMAKE_INSTALL_DATADIR}/kinograph)
file(CREATE_LINK ${PROJECT_SOURCE_DIR}/robots
     ${PROJECT_BINARY_DIR}/${CMAKE_INSTALL_DATADIR}/kinograph/robots SYMBOLIC)

# Called after every module is defined.
function(kinograph_install_package)
  get_property(modules GLOBAL PROPERTY KINOGRAPH_MODULES)
  add_library(kinograph_library INTERFACE)
  target_link_libraries(kinograph_library INTERFACE ${modules})
  kinograph_export_module(kinograph_library kinograph)

  foreach(dir kinograph render daemon)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${KINOGRAPH_INSTALL_INCLUDEDIR}/${dir}
      FILES_MATCHING PATTERN "*.h")
  endforeach()
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/robots/ DESTINATION ${KINOGRAPH_INSTALL_DATADIR}/robots)
  install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/kinograph)

  install(EXPORT kinographTargets NAMESPACE kinograph:: DESTINATION ${KINOGRAPH_INSTALL_CMAKEDIR})
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/kinographConfig.cmake.in
    ${PROJECT_BINARY_DIR}/kinographConfig.cmake
    INSTALL_DESTINATION ${KINOGRAPH_INSTALL_CMAKEDIR}
    PATH_VARS KINOGRAPH_INSTALL_DATADIR)
  # 0.x: a new minor version may break the API, so only the same minor version matches.
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/kinographConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/kinographConfig.cmake
    ${PROJECT_BINARY_DIR}/kinographConfigVersion.cmake
    ${PROJECT_SOURCE_DIR}/cmake/LibraryDependencies.cmake
    DESTINATION ${KINOGRAPH_INSTALL_CMAKEDIR})
endfunction()
