# The Debian package (CPack DEB): `cmake --build B --target package` in a tree configured for it
# makes B/softsight_<version>_<arch>.deb holding the program and its plugins, the shared libraries,
# the public headers, the CMake package, the pkg-config files, the Python module (in
# /usr/lib/python3/dist-packages, where Debian's python3 looks) and the man pages.
# scripts/package-deb.sh configures such a tree (build-deb/) and makes it:
#   -DCMAKE_INSTALL_PREFIX=/usr        Debian's folders: /usr/lib/<arch>, lib/python3/dist-packages
#   -DSOFTSIGHT_MAN_PAGES=ON           man pages from --help (help2man)
# scripts/check-deb.sh installs it in a clean Debian 12 root and uses it there.

# ---- Man pages -------------------------------------------------------------------------------
# Off by default: they take a run of every command's --help (16 s on a loaded 2-core machine)
# that the tests and CI do not need.
option(SOFTSIGHT_MAN_PAGES "Generate man pages from --help with help2man, and install them" OFF)
if(SOFTSIGHT_MAN_PAGES)
  find_program(SOFTSIGHT_HELP2MAN help2man)
  if(NOT SOFTSIGHT_HELP2MAN)
    message(FATAL_ERROR "SOFTSIGHT_MAN_PAGES=ON needs help2man (sudo apt-get install help2man, "
                        "or scripts/setup.sh deb)")
  endif()
  set(_softsight_man_dir ${PROJECT_BINARY_DIR}/man)
  add_custom_command(
    OUTPUT ${_softsight_man_dir}/softsight.1.gz
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:softsight> -DHELP2MAN=${SOFTSIGHT_HELP2MAN}
            -DOUT=${_softsight_man_dir} -P ${PROJECT_SOURCE_DIR}/cmake/man_pages.cmake
    DEPENDS softsight softsight_plugin_commands softsight_plugin_live
            ${PROJECT_SOURCE_DIR}/cmake/man_pages.cmake
    COMMENT "help2man: softsight(1) and a page per command"
    VERBATIM)
  add_custom_target(softsight_man_pages ALL DEPENDS ${_softsight_man_dir}/softsight.1.gz)
  install(DIRECTORY ${_softsight_man_dir}/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
          FILES_MATCHING PATTERN "*.1.gz")
endif()
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

# ---- CPack: the .deb ---------------------------------------------------------------------------
set(SOFTSIGHT_PACKAGE_MAINTAINER "softsight <dev@softsight>" CACHE STRING
    "The Maintainer field of the Debian package")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME softsight)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${SOFTSIGHT_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION
    "softsight finds coloured (or white, or black) markers on a soft actuator, frame by frame, to a
fraction of a pixel, and turns them into its bending angle, radius of curvature, arc length and
bending distance, in pixels and millimetres: in batch on videos, live on a camera with an overlay
window, from Python, and closing the control loop over a serial link.
This package holds the program (softsight), its C++ library (shared libraries, headers, CMake
package, pkg-config files) and the Python module.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # softsight_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Depends: the libraries the binaries link (dpkg-shlibdeps), and what the rest needs:
#  - the Python module: this build's Python 3.X and numpy;
#  - the headers, CMake package and pkg-config files: OpenCV's (the public headers include
#    opencv2/core.hpp; OpenCVConfig.cmake and opencv4.pc are libopencv-dev's).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)  # A shlibs file for our libraries, and ldconfig.
set(_softsight_deb_depends "libopencv-dev")
if(SOFTSIGHT_BUILD_PYTHON)
  set(_softsight_py "${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}")
  math(EXPR _softsight_py_next "${Python3_VERSION_MINOR} + 1")
  string(APPEND _softsight_deb_depends
         ", python3 (>= ${_softsight_py}), python3 (<< ${Python3_VERSION_MAJOR}.${_softsight_py_next}), python3-numpy")
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${_softsight_deb_depends}")
# What some features use when present: Dask batches, the stream's subscriber, progress bars,
# tables as pandas frames, and the tools to build against the library.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "python3-dask, python3-distributed, python3-zmq, python3-tqdm, python3-pandas, cmake, pkg-config, g++")
# The package is for /usr: checked when cpack runs (cmake/package_check.cmake).
set(CPACK_SOFTSIGHT_INSTALL_PREFIX "${CMAKE_INSTALL_PREFIX}")
set(CPACK_SOFTSIGHT_MAN_PAGES "${SOFTSIGHT_MAN_PAGES}")
set(CPACK_SOFTSIGHT_SHARED "${BUILD_SHARED_LIBS}")
set(CPACK_PROJECT_CONFIG_FILE ${PROJECT_SOURCE_DIR}/cmake/package_check.cmake)
include(CPack)
