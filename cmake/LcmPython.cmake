# The LCM message types as the Python package `kinograph` (lcm-gen --python of every
# lcmtypes/*.lcm), written to <build>/share/kinograph/python and installed to
# share/kinograph/python beside the client (python/). Needs only lcm-gen, so it is always built.
# Sets KINOGRAPH_PYTHON_DIR (the build tree's copy) and makes target kinograph_lcmtypes_python.
set(KINOGRAPH_PYTHON_DIR ${PROJECT_BINARY_DIR}/${CMAKE_INSTALL_DATADIR}/kinograph/python)
file(GLOB lcm_files CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/lcmtypes/*.lcm)
list(SORT lcm_files)
# lcm-gen writes one module per struct (named after it) and an __init__.py importing them all.
set(python_sources ${KINOGRAPH_PYTHON_DIR}/kinograph/__init__.py)
foreach(lcm_file ${lcm_files})
  file(STRINGS ${lcm_file} struct_lines REGEX "^struct [A-Za-z0-9_]+")
  foreach(line ${struct_lines})
    string(REGEX REPLACE "^struct ([A-Za-z0-9_]+).*" "\\1" type "${line}")
    list(APPEND python_sources ${KINOGRAPH_PYTHON_DIR}/kinograph/${type}.py)
  endforeach()
endforeach()
# The package directory is emptied first: lcm-gen appends to an existing __init__.py.
add_custom_command(OUTPUT ${python_sources}
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${KINOGRAPH_PYTHON_DIR}/kinograph
  COMMAND ${CMAKE_COMMAND} -E make_directory ${KINOGRAPH_PYTHON_DIR}
  COMMAND ${LCM_GEN} --python --ppath ${KINOGRAPH_PYTHON_DIR} ${lcm_files}
  DEPENDS ${lcm_files}
  COMMENT "lcm-gen --python"
  VERBATIM)
add_custom_target(kinograph_lcmtypes_python ALL DEPENDS ${python_sources})
install(FILES ${python_sources} DESTINATION ${KINOGRAPH_INSTALL_DATADIR}/python/kinograph)
