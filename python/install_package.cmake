# Run by `cmake --install` (python/CMakeLists.txt's install(CODE)): installs the softsight Python
# package where the install prefix's Python finds it. The prefix is known only now (--prefix), and
# the place depends on it: ~/.local gets the user site (`python3 -m site --user-site`), /usr
# Debian's lib/python3/dist-packages, /usr/local and a virtual environment theirs
# (python/python_install_dir.py says which). With SOFTSIGHT_PYTHON_SITE_DIR set at configure
# time, that directory instead (relative: under the prefix).
#
# In (set by the install(CODE) before including this): SOFTSIGHT_PYTHON, SOFTSIGHT_PYTHON_SITE_DIR,
# SOFTSIGHT_PYTHON_SITE_SCRIPT, SOFTSIGHT_PYTHON_MODULE (the built _core*.so) and its installed rpath
# SOFTSIGHT_PYTHON_MODULE_RPATH,
# SOFTSIGHT_PYTHON_SOURCES (the package's other files), SOFTSIGHT_PYTHON_DIST_INFO (its metadata).
cmake_policy(VERSION 3.22)  # cmake_install.cmake runs under CMake's oldest policies.
if(SOFTSIGHT_PYTHON_SITE_DIR)
  set(_dir "${SOFTSIGHT_PYTHON_SITE_DIR}")
  set(_found "given")
else()
  execute_process(
    COMMAND "${SOFTSIGHT_PYTHON}" "${SOFTSIGHT_PYTHON_SITE_SCRIPT}" "${CMAKE_INSTALL_PREFIX}"
    OUTPUT_VARIABLE _answer OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "softsight: ${SOFTSIGHT_PYTHON} could not say where its packages go "
                        "under ${CMAKE_INSTALL_PREFIX} (${_rc})")
  endif()
  string(REPLACE "\n" ";" _answer "${_answer}")
  list(GET _answer 0 _dir)
  list(GET _answer 1 _found)
endif()
if(IS_ABSOLUTE "${_dir}")
  set(_site "${_dir}")
else()
  set(_site "${CMAKE_INSTALL_PREFIX}/${_dir}")
endif()

file(INSTALL DESTINATION "${_site}/softsight" TYPE MODULE FILES "${SOFTSIGHT_PYTHON_MODULE}")
get_filename_component(_module_name "${SOFTSIGHT_PYTHON_MODULE}" NAME)
# The built module looks for the shared libraries in the build tree; installed, from its own
# place (SOFTSIGHT_PYTHON_MODULE_RPATH, relative to $ORIGIN), or nowhere (static libraries, or
# shared ones in a system folder). CMake leaves room in the built module's rpath for this one.
if(CMAKE_VERSION VERSION_GREATER_EQUAL 3.21)
  file(RPATH_SET FILE "$ENV{DESTDIR}${_site}/softsight/${_module_name}"
       NEW_RPATH "${SOFTSIGHT_PYTHON_MODULE_RPATH}")
endif()
if(CMAKE_INSTALL_DO_STRIP)
  execute_process(COMMAND strip "$ENV{DESTDIR}${_site}/softsight/${_module_name}")
endif()
file(INSTALL DESTINATION "${_site}/softsight" TYPE FILE FILES ${SOFTSIGHT_PYTHON_SOURCES})
file(INSTALL DESTINATION "${_site}" TYPE DIRECTORY FILES "${SOFTSIGHT_PYTHON_DIST_INFO}")

# For the summary at the end of the install (cmake/install_summary.cmake).
set(SOFTSIGHT_INSTALLED_PYTHON_SITE "${_site}")
set(SOFTSIGHT_INSTALLED_PYTHON_FOUND "${_found}")
if(_found STREQUAL "found")
  message(STATUS "softsight: the Python package is in ${_site}, where ${SOFTSIGHT_PYTHON} finds it")
elseif(_found STREQUAL "PYTHONPATH")
  message(STATUS "softsight: the Python package is in ${_site}, which Python does not search: "
                 "PYTHONPATH=${_site} (or install with --prefix ~/.local, /usr/local or a "
                 "virtual environment's)")
endif()
