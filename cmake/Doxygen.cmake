# Optional: the API reference (HTML) of the public headers, target `docs`, built when Debian's
# doxygen is present (skipped, with a note, when it is not). No graphs, so Graphviz is not
# needed. Doxygen's warnings go to ${KINOGRAPH_DOXYGEN_WARNINGS}; tests/docs checks there are
# none. Sets KINOGRAPH_DOXYFILE for that test.
find_package(Doxygen QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "kinograph: no API reference (needs doxygen)")
  return()
endif()
set(KINOGRAPH_DOXYGEN_WARNINGS ${CMAKE_BINARY_DIR}/docs/doxygen_warnings.log)
set(DOXYGEN_PROJECT_NAME kinograph)
set(DOXYGEN_PROJECT_NUMBER ${PROJECT_VERSION})
set(DOXYGEN_PROJECT_BRIEF "Kinodynamic motion planning with factor graphs")
set(DOXYGEN_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/docs)
set(DOXYGEN_FILE_PATTERNS *.h)
set(DOXYGEN_EXTRACT_ALL YES)
# Every public declaration has a one- or two-line doc; parameters are not listed one by one.
set(DOXYGEN_WARN_IF_UNDOCUMENTED NO)
set(DOXYGEN_WARN_NO_PARAMDOC NO)
set(DOXYGEN_WARN_LOGFILE ${KINOGRAPH_DOXYGEN_WARNINGS})
set(DOXYGEN_HAVE_DOT NO)
set(DOXYGEN_GENERATE_LATEX NO)
set(DOXYGEN_QUIET YES)
set(DOXYGEN_STRIP_FROM_PATH ${PROJECT_SOURCE_DIR})
set(DOXYGEN_STRIP_FROM_INC_PATH ${PROJECT_SOURCE_DIR})
doxygen_add_docs(docs
  ${PROJECT_SOURCE_DIR}/kinograph ${PROJECT_SOURCE_DIR}/daemon ${PROJECT_SOURCE_DIR}/render
  ${PROJECT_SOURCE_DIR}/sim ${PROJECT_SOURCE_DIR}/tools ${PROJECT_SOURCE_DIR}/lcmtypes/safe_decode.h
  COMMENT "Doxygen: API reference in ${CMAKE_BINARY_DIR}/docs/html")
set(KINOGRAPH_DOXYFILE ${CMAKE_BINARY_DIR}/Doxyfile.docs)
