# The library for other projects (`cmake --install build --prefix DIR`):
#  - the public headers (include/softsight/, the API; what only the program or the tests use
#    lives in src/), softsight/softsight.h (all of them) and the generated softsight/version.h;
#  - the libraries of the modules below the program (core ... pipeline; gui, stream and the
#    commands are the program's own): shared and versioned (libsoftsight_<module>.so.0.1, with
#    the libsoftsight_<module>.so link to build with), or static with -DBUILD_SHARED_LIBS=OFF;
#    imported targets softsight::<module> and softsight::softsight (all of them) for
#    find_package(softsight);
#  - a pkg-config file, softsight.pc, for builds without CMake.
# scripts/check-install.sh builds outside programs against an installed tree (ctest install.*).
include(CMakePackageConfigHelpers)

set(_softsight_installed_targets "")
foreach(module IN LISTS SOFTSIGHT_INSTALLED_MODULES)
  list(APPEND _softsight_installed_targets softsight_${module})
endforeach()

# softsight::softsight: every installed module (the pipeline links all of the others).
add_library(softsight_all INTERFACE)
target_link_libraries(softsight_all INTERFACE softsight_pipeline)
set_target_properties(softsight_all PROPERTIES EXPORT_NAME softsight)
add_library(softsight::softsight ALIAS softsight_all)

install(TARGETS ${_softsight_installed_targets} softsight_all EXPORT softsightTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT library
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT library
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/softsight DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT library FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/softsight/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/softsight COMPONENT library)

set(SOFTSIGHT_CMAKE_PACKAGE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/softsight)
install(EXPORT softsightTargets NAMESPACE softsight:: DESTINATION ${SOFTSIGHT_CMAKE_PACKAGE_DIR}
        COMPONENT library)
configure_package_config_file(cmake/softsightConfig.cmake.in
  ${PROJECT_BINARY_DIR}/softsightConfig.cmake INSTALL_DESTINATION ${SOFTSIGHT_CMAKE_PACKAGE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/softsightConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)  # 0.x: a minor version may change the API.
install(FILES ${PROJECT_BINARY_DIR}/softsightConfig.cmake ${PROJECT_BINARY_DIR}/softsightConfigVersion.cmake
        DESTINATION ${SOFTSIGHT_CMAKE_PACKAGE_DIR} COMPONENT library)

# pkg-config: relocatable (prefix from the .pc file's own place), so --prefix at install time
# moves it. Every dependency is in Requires, as a static library needs (shared ones need less),
# and the libraries are listed so that each comes before the ones it uses.
file(RELATIVE_PATH SOFTSIGHT_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
string(REGEX REPLACE "/$" "" SOFTSIGHT_PC_TO_PREFIX "${SOFTSIGHT_PC_TO_PREFIX}")
set(SOFTSIGHT_PC_LIBS "")
foreach(module IN ITEMS pipeline config io sim calib control track geometry core)
  string(APPEND SOFTSIGHT_PC_LIBS " -lsoftsight_${module}")
endforeach()
configure_file(cmake/softsight.pc.in ${PROJECT_BINARY_DIR}/softsight.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/softsight.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
        COMPONENT library)

# ctest install.*: install this tree into build/install-check/prefix, then build and run an outside
# program against it with CMake and with pkg-config, and pip-install the Python package into a
# fresh virtual environment (scripts/check-install.sh). Not in the instrumented tree: packaging
# is the same there, and an ASan-built library would need ASan in the outside program too.
if(SOFTSIGHT_BUILD_TESTS AND NOT SOFTSIGHT_SANITIZE AND NOT SOFTSIGHT_FUZZ)
  set(_softsight_check ${PROJECT_SOURCE_DIR}/scripts/check-install.sh)
  set(_softsight_work ${PROJECT_BINARY_DIR}/install-check)
  add_test(NAME install.prefix COMMAND bash ${_softsight_check} prefix ${PROJECT_BINARY_DIR} ${_softsight_work})
  set_tests_properties(install.prefix PROPERTIES FIXTURES_SETUP softsight_installed TIMEOUT 120)
  foreach(mode IN ITEMS cmake pkg-config)
    string(REPLACE "-" "_" name ${mode})
    add_test(NAME install.${name} COMMAND bash ${_softsight_check} ${mode} ${PROJECT_BINARY_DIR} ${_softsight_work})
    set_tests_properties(install.${name} PROPERTIES FIXTURES_REQUIRED softsight_installed TIMEOUT 240)
  endforeach()
  if(SOFTSIGHT_BUILD_PYTHON)
    add_test(NAME install.pip COMMAND bash ${_softsight_check} pip ${PROJECT_BINARY_DIR} ${_softsight_work})
    set_tests_properties(install.pip PROPERTIES TIMEOUT 240
                         ENVIRONMENT "SOFTSIGHT_PYTHON=${Python3_EXECUTABLE}")
  endif()
endif()
