# The library for other projects (`cmake --install build --prefix DIR`):
#  - the public headers (include/softsight/, the API; what only the program or the tests use
#    lives in src/), softsight/softsight.h (all of them) and the generated softsight/version.h;
#  - the libraries of the modules below the program (core ... pipeline; gui, stream and the
#    commands are the program's own): shared and versioned (libsoftsight_<module>.so.0.1, with
#    the libsoftsight_<module>.so link to build with), or static with -DBUILD_SHARED_LIBS=OFF;
#    imported targets softsight::<module> and softsight::softsight (all of them) for
#    find_package(softsight);
#  - pkg-config files: softsight.pc (everything) and softsight-<module>.pc (one module and the
#    modules it needs), for builds without CMake.
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
# Whether io links Aravis (GenICam cameras): softsightConfig.cmake finds it for static users.
set(SOFTSIGHT_WITH_ARAVIS OFF)
if(ARAVIS_FOUND)
  set(SOFTSIGHT_WITH_ARAVIS ON)
endif()
configure_package_config_file(cmake/softsightConfig.cmake.in
  ${PROJECT_BINARY_DIR}/softsightConfig.cmake INSTALL_DESTINATION ${SOFTSIGHT_CMAKE_PACKAGE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/softsightConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)  # 0.x: a minor version may change the API.
install(FILES ${PROJECT_BINARY_DIR}/softsightConfig.cmake ${PROJECT_BINARY_DIR}/softsightConfigVersion.cmake
        DESTINATION ${SOFTSIGHT_CMAKE_PACKAGE_DIR} COMPONENT library)

# pkg-config: relocatable (prefix from the .pc file's own place), so --prefix at install time
# moves it (a tree configured for /usr, the .deb's, writes /usr). One file per module,
# softsight-<module>.pc, whose Requires are the softsight modules its public headers use, and
# softsight.pc for all of them: `pkg-config --libs softsight-track` is -lsoftsight_track
# -lsoftsight_core -lopencv_core. What a module calls only inside (OpenCV's other modules,
# yaml-cpp, libserial, FFmpeg) is the shared library's own business: in Requires.private OpenCV
# (the public headers include its headers: its -I comes with --cflags), in Libs.private the rest
# as plain -l flags (a user needs neither their headers nor their .pc files). The public headers
# call only OpenCV's core, so that is the one OpenCV library in Libs. A static build's libraries
# need all of their dependencies linked: there they are all Requires.
file(RELATIVE_PATH SOFTSIGHT_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
string(REGEX REPLACE "/$" "" SOFTSIGHT_PC_TO_PREFIX "${SOFTSIGHT_PC_TO_PREFIX}")
set(SOFTSIGHT_PC_PREFIX "\${pcfiledir}/${SOFTSIGHT_PC_TO_PREFIX}")
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  # The system's own prefix (the .deb): plain paths, which pkg-config leaves out of its flags.
  set(SOFTSIGHT_PC_PREFIX /usr)
endif()
# What each module uses inside, as pkg-config packages (Requires) and as -l flags (Libs.private).
set(_softsight_pc_core opencv4)
set(_softsight_pc_geometry "")
set(_softsight_pc_track opencv4)
set(_softsight_pc_sim opencv4)
set(_softsight_pc_calib opencv4)
set(_softsight_pc_control libserial)
set(_softsight_pc_io opencv4 libavutil libavcodec libavformat libswscale)
# Aravis (GenICam cameras), when the build has it: static users link it too.
if(ARAVIS_FOUND)
  list(APPEND _softsight_pc_io aravis-0.8)
endif()
set(_softsight_pc_config opencv4 yaml-cpp)
set(_softsight_pc_pipeline opencv4)
set(_softsight_libs_core "")
set(_softsight_libs_geometry "")
set(_softsight_libs_track -lopencv_imgproc)
set(_softsight_libs_sim -lopencv_calib3d -lopencv_imgproc)
set(_softsight_libs_calib -lopencv_calib3d -lopencv_imgproc)
set(_softsight_libs_control -lserial -pthread)
set(_softsight_libs_io -lopencv_videoio -lopencv_imgcodecs -lopencv_imgproc -lavformat -lavcodec -lswscale -lavutil
    -pthread)
if(ARAVIS_FOUND)
  list(APPEND _softsight_libs_io -laravis-0.8 -lgobject-2.0 -lglib-2.0)
endif()
set(_softsight_libs_config -lyaml-cpp -lopencv_imgcodecs)
set(_softsight_libs_pipeline -lopencv_imgproc)
set(_softsight_module_text_core "value types, errors, number formatting")
set(_softsight_module_text_geometry "the paper's measurements on marker positions")
set(_softsight_module_text_track "the colour and template trackers")
set(_softsight_module_text_sim "rendered scenes with exact ground truth")
set(_softsight_module_text_calib "camera and stereo calibration, triangulation")
set(_softsight_module_text_control "the controller, the board link, the simulated rig")
set(_softsight_module_text_io "frame sources and writers, CSV, plots")
set(_softsight_module_text_config "the YAML configuration")
set(_softsight_module_text_pipeline "tracking sessions and runs, sinks, summaries")
# OpenCV's core, for the public headers' inline code: -L only when it is not in a system folder.
get_target_property(_softsight_cv_core opencv_core LOCATION)
get_filename_component(_softsight_cv_dir "${_softsight_cv_core}" DIRECTORY)
set(_softsight_cv_core_libs -lopencv_core)
if(NOT _softsight_cv_dir IN_LIST CMAKE_CXX_IMPLICIT_LINK_DIRECTORIES)
  set(_softsight_cv_core_libs "-L${_softsight_cv_dir} -lopencv_core")
endif()

function(softsight_write_pc name description requires own_libs externals external_libs)
  set(PC_NAME ${name})
  set(PC_DESCRIPTION "${description}")
  set(PC_LIBS "${own_libs}")
  if(BUILD_SHARED_LIBS)
    set(PC_REQUIRES "${requires}")
    set(PC_REQUIRES_PRIVATE "")
    if("opencv4" IN_LIST externals)
      set(PC_REQUIRES_PRIVATE opencv4)
    endif()
    set(PC_LIBS_PRIVATE "${external_libs}")
  else()
    set(PC_REQUIRES ${requires} ${externals})
    set(PC_REQUIRES_PRIVATE "")
    set(PC_LIBS_PRIVATE "")
  endif()
  foreach(var PC_REQUIRES PC_REQUIRES_PRIVATE PC_LIBS PC_LIBS_PRIVATE)
    list(REMOVE_DUPLICATES ${var})
    string(REPLACE ";" " " ${var} "${${var}}")
  endforeach()
  configure_file(${PROJECT_SOURCE_DIR}/cmake/softsight.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/${name}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/pkgconfig/${name}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
          COMPONENT library)
endfunction()

set(_softsight_all_modules "")
foreach(module IN LISTS SOFTSIGHT_INSTALLED_MODULES)
  set(requires "")
  get_target_property(deps softsight_${module} INTERFACE_LINK_LIBRARIES)
  foreach(dep IN LISTS deps)
    if(dep MATCHES "^softsight_([a-z]+)$")
      list(APPEND requires softsight-${CMAKE_MATCH_1})
    endif()
  endforeach()
  set(libs "-L\${libdir} -lsoftsight_${module}")
  if(module STREQUAL "core")
    string(APPEND libs " ${_softsight_cv_core_libs}")
  endif()
  if(NOT BUILD_SHARED_LIBS AND module MATCHES "^(control|io)$")
    string(APPEND libs " -pthread")  # Their threads (a static library's users link what it calls).
  endif()
  set(external_libs ${_softsight_libs_${module}})
  if(NOT BUILD_SHARED_LIBS)
    set(external_libs "")
  endif()
  softsight_write_pc(softsight-${module} "softsight's ${module} library: ${_softsight_module_text_${module}}"
                     "${requires}" "${libs}" "${_softsight_pc_${module}}" "${external_libs}")
  list(APPEND _softsight_all_modules softsight-${module})
endforeach()
# softsight.pc: every module (the pipeline needs all of the others; named each, so that a program
# calling any of them links it).
list(REVERSE _softsight_all_modules)
softsight_write_pc(softsight "${PROJECT_DESCRIPTION} (the library: markers, measurements, sessions, control)"
                   "${_softsight_all_modules}" "" "" "")

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
