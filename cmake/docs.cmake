# The API reference (docs/api.md): `cmake --build build --target docs` runs Doxygen over the public
# headers into build/docs/html/index.html. Not part of the default build, the tests or CI; needs
# doxygen (`sudo apt-get install doxygen`, or `scripts/setup.sh docs`).
find_package(Doxygen QUIET)
set(SOFTSIGHT_DOCS_DIR ${PROJECT_BINARY_DIR}/docs)
configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${SOFTSIGHT_DOCS_DIR}/Doxyfile @ONLY)
if(DOXYGEN_FOUND)
  add_custom_target(docs
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${SOFTSIGHT_DOCS_DIR}/html
    COMMAND Doxygen::doxygen ${SOFTSIGHT_DOCS_DIR}/Doxyfile
    COMMAND ${CMAKE_COMMAND} -E echo "API reference: ${SOFTSIGHT_DOCS_DIR}/html/index.html"
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    COMMENT "Doxygen: the API reference of include/softsight/"
    VERBATIM)
else()
  add_custom_target(docs
    COMMAND ${CMAKE_COMMAND} -E echo "docs: doxygen not found (sudo apt-get install doxygen), then configure again"
    COMMAND ${CMAKE_COMMAND} -E false
    VERBATIM)
endif()
