# Run last by `cmake --install` (CMakeLists.txt's install(CODE)): says what the shell needs for the
# installed tree to be found, only what is not already so. A prefix such as ~/.local is on none of
# pkg-config's default paths (`pkg-config --variable pc_path pkg-config`), and its bin/ may not be
# on PATH; find_package(softsight) searches the parents of PATH's bin/ folders and the system
# prefixes. The Python package's line comes from python/install_package.cmake.
#
# In (set by the install(CODE) before including this): SOFTSIGHT_PKG_CONFIG (pkg-config, may be
# empty), SOFTSIGHT_BINDIR, SOFTSIGHT_LIBDIR (relative to the prefix).
cmake_policy(VERSION 3.22)  # cmake_install.cmake runs under CMake's oldest policies (IN_LIST).
if(NOT "$ENV{DESTDIR}" STREQUAL "")
  return()  # Staged for a package: the paths are the package's business.
endif()
set(_prefix "${CMAKE_INSTALL_PREFIX}")
set(_bin "${_prefix}/${SOFTSIGHT_BINDIR}")
set(_pc_dir "${_prefix}/${SOFTSIGHT_LIBDIR}/pkgconfig")

string(REPLACE ":" ";" _path "$ENV{PATH}")
set(_bin_on_path OFF)
foreach(_entry IN LISTS _path)
  if(_entry AND _entry STREQUAL _bin)
    set(_bin_on_path ON)
  endif()
endforeach()

set(_pc_found OFF)
if(SOFTSIGHT_PKG_CONFIG)
  execute_process(COMMAND "${SOFTSIGHT_PKG_CONFIG}" --variable pc_path pkg-config
                  OUTPUT_VARIABLE _pc_path OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  string(REPLACE ":" ";" _pc_path "${_pc_path}:$ENV{PKG_CONFIG_PATH}")
  foreach(_entry IN LISTS _pc_path)
    if(_entry AND _entry STREQUAL _pc_dir)
      set(_pc_found ON)
    endif()
  endforeach()
endif()

set(_cmake_found OFF)
if(_bin_on_path OR _prefix STREQUAL "/usr" OR _prefix STREQUAL "/usr/local")
  set(_cmake_found ON)
endif()
string(REPLACE ":" ";" _cmake_prefixes "$ENV{CMAKE_PREFIX_PATH}")
if(_prefix IN_LIST _cmake_prefixes)
  set(_cmake_found ON)
endif()

set(_lines "")
if(NOT _bin_on_path)
  list(APPEND _lines "  export PATH=\"${_bin}:$PATH\"   # the program")
endif()
if(NOT _pc_found)
  list(APPEND _lines "  export PKG_CONFIG_PATH=\"${_pc_dir}\"   # pkg-config softsight")
endif()
if(NOT _cmake_found)
  list(APPEND _lines "  export CMAKE_PREFIX_PATH=\"${_prefix}\"   # find_package(softsight)")
endif()
if(SOFTSIGHT_INSTALLED_PYTHON_FOUND STREQUAL "PYTHONPATH")
  list(APPEND _lines "  export PYTHONPATH=\"${SOFTSIGHT_INSTALLED_PYTHON_SITE}\"   # import softsight")
endif()
if(_lines)
  string(REPLACE ";" "\n" _lines "${_lines}")
  message(STATUS "softsight: installed into ${_prefix}; to use it from there:\n${_lines}")
else()
  message(STATUS "softsight: installed into ${_prefix}; the program, pkg-config, "
                 "find_package and Python find it as they are")
endif()
