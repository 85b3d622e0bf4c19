# Optional: the LCM message types as a Java jar for lcm-spy, built when a JDK (openjdk-17-jdk)
# and LCM's Java library (liblcm-java) are present; `kinograph-spy` starts lcm-spy with it.
# Expects KINOGRAPH_LCM_TYPES and KINOGRAPH_DRAKE_LCM_TYPES (type names) and LCM_GEN; makes
# target kinograph_lcmtypes_jar holding both packages, so lcm-spy decodes Drake's channels too.
find_package(Java 1.8 COMPONENTS Development QUIET)
find_file(KINOGRAPH_LCM_JAR lcm.jar PATHS /usr/share/java NO_DEFAULT_PATH)
if(NOT Java_FOUND OR NOT KINOGRAPH_LCM_JAR)
  message(STATUS "kinograph: no lcm-spy jar (needs a JDK and liblcm-java)")
  return()
endif()
include(UseJava)

set(java_dir ${CMAKE_CURRENT_BINARY_DIR}/java)
set(java_sources)
set(lcm_files)
foreach(type ${KINOGRAPH_LCM_TYPES})
  list(APPEND java_sources ${java_dir}/kinograph/${type}.java)
  list(APPEND lcm_files ${CMAKE_CURRENT_SOURCE_DIR}/${type}.lcm)
endforeach()
foreach(type ${KINOGRAPH_DRAKE_LCM_TYPES})
  list(APPEND java_sources ${java_dir}/drake/${type}.java)
  list(APPEND lcm_files ${CMAKE_CURRENT_SOURCE_DIR}/drake/${type}.lcm)
endforeach()
add_custom_command(OUTPUT ${java_sources}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${java_dir}
  COMMAND ${LCM_GEN} --java --jpath ${java_dir} ${lcm_files}
  DEPENDS ${lcm_files}
  COMMENT "lcm-gen --java"
  VERBATIM)
add_jar(kinograph_lcmtypes_jar SOURCES ${java_sources} INCLUDE_JARS ${KINOGRAPH_LCM_JAR}
        OUTPUT_NAME kinograph_lcmtypes)
install_jar(kinograph_lcmtypes_jar DESTINATION ${KINOGRAPH_INSTALL_DATADIR}/java)
