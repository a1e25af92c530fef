# Run by cpack before it packages (CPACK_PROJECT_CONFIG_FILE, cmake/package.cmake): a .deb is made
# only from a tree configured for Debian's folders, or its files would land where nothing finds
# them (the Python module in /usr/lib/python3.X/dist-packages, which Debian's python3 does not
# search). scripts/package-deb.sh configures such a tree.
if(CPACK_GENERATOR STREQUAL "DEB")
  set(_problems "")
  if(NOT CPACK_SOFTSIGHT_INSTALL_PREFIX STREQUAL "/usr")
    string(APPEND _problems " -DCMAKE_INSTALL_PREFIX=/usr (it is ${CPACK_SOFTSIGHT_INSTALL_PREFIX})")
  endif()
  if(NOT CPACK_SOFTSIGHT_MAN_PAGES)
    string(APPEND _problems " -DSOFTSIGHT_MAN_PAGES=ON")
  endif()
  if(NOT CPACK_SOFTSIGHT_SHARED)
    string(APPEND _problems " -DBUILD_SHARED_LIBS=ON")
  endif()
  if(_problems)
    message(FATAL_ERROR "the Debian package needs a tree configured with${_problems}: "
                        "scripts/package-deb.sh makes one")
  endif()
endif()
