# Helpers that keep each module's CMakeLists.txt to a few lines.

# Unity build (SOFTSIGHT_UNITY_BUILD, on by default): a module's files are compiled in batches of
# up to 8 (CMake's UNITY_BUILD), so the heavy headers they share are parsed, and their inline code
# compiled and optimised, once per batch instead of once per file. CLI11 is header-only: its code
# was compiled again in each of the 20 command files (8-16 s of CPU each, 214 s in all; one batch
# of all 20 took 33 s). Files batched together must not define the same name in an anonymous
# namespace (or a `static` one): a helper two test files need lives in a shared test header
# (core/test_util.h, app/program_test_util.h, ...), and one that only looks alike gets a name of
# its own. A new clash shows as "redefinition of '...{anonymous}::NAME'". Every target is batched;
# the gui library keeps live_window.cc out of its batches (src/gui/CMakeLists.txt says why).
function(softsight_use_unity_build target)
  if(SOFTSIGHT_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
endfunction()

# softsight_add_library(<module> SOURCES ... DEPS ... [PRIVATE_DEPS ...])
# Creates target softsight_<module>. Public headers live in include/softsight/<module>/,
# private ones beside the sources in src/<module>/ (included as "<module>/x.h").
# DEPS: what the module's public headers use (softsight modules, OpenCV's core), passed on to
# whatever links it; PRIVATE_DEPS: what only its sources use (imgproc, yaml-cpp, libserial,
# FFmpeg). A module of the installed library (SOFTSIGHT_INSTALLED_MODULES) is a shared, versioned
# library under BUILD_SHARED_LIBS (libsoftsight_<module>.so.<major>.<minor>; a static one
# otherwise); the program's own modules (stream, gui, cli) are always static, linked into its
# plugins, so a plugin loads only the system libraries it calls (src/app/CMakeLists.txt).
function(softsight_add_library module)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  set(target softsight_${module})
  if(BUILD_SHARED_LIBS AND module IN_LIST SOFTSIGHT_INSTALLED_MODULES)
    add_library(${target} SHARED ${ARG_SOURCES})
    # 0.x: a minor version may change the ABI as it may the API (softsightConfigVersion's
    # SameMinorVersion), so the soname carries both: libsoftsight_core.so.0.1.
    set_target_properties(${target} PROPERTIES VERSION ${PROJECT_VERSION}
                          SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
                          INSTALL_RPATH "${SOFTSIGHT_LIB_RPATH}"
                          # Copies beside each other (a pip install reusing this tree: setup.py)
                          # find each other before the build tree's.
                          BUILD_RPATH "$ORIGIN")
    # A library must name every library it calls (a PRIVATE_DEPS left out fails here, not in
    # the program that links it). Not with the sanitizers: their runtime is the executable's.
    if(NOT SOFTSIGHT_SANITIZE AND NOT SOFTSIGHT_FUZZ)
      target_link_options(${target} PRIVATE LINKER:--no-undefined)
    endif()
    # Bound at load (-z now), whatever the loader's mode: the launcher dlopen()s a command's
    # plugin lazily (app/main.cc), so that the ~250 system libraries' functions are bound only
    # when called, and a library of this project whose copy lacks a function another calls (a
    # stale install) fails there, with the launcher's message, not mid-run. ~2M instructions.
    target_link_options(${target} PRIVATE LINKER:-z,now)
  else()
    add_library(${target} STATIC ${ARG_SOURCES})
  endif()
  target_include_directories(${target}
    PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(${target} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  # softsight::<module>, the same name in this tree and for find_package(softsight) users.
  add_library(softsight::${module} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module})
  # Shared libraries, and the program's command plugins and the Python module (shared objects
  # that link the static ones), need position-independent code. Every symbol keeps default
  # visibility: the tests call a module's internal functions too, and the API needs no export
  # list to keep in step. -fno-semantic-interposition keeps GCC inlining and calling directly
  # between a library's own functions (which plain -fPIC would forbid, for the sake of
  # replacing one of them from outside, which softsight does not support), so the programs stay
  # as fast as with static libraries.
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  softsight_use_unity_build(${target})
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU>:-fno-semantic-interposition>)
  # SOFTSIGHT_O1_MODULES: these modules at -O1 whatever the tree's level (the instrumented tree is
  # -O0 but for the modules its tests spend their time in: scripts/sanitizer/configure.sh).
  if(module IN_LIST SOFTSIGHT_O1_MODULES)
    target_compile_options(${target} PRIVATE -O1)
  endif()
endfunction()

# The tests' precompiled header (SOFTSIGHT_UNITY_BUILD goes with it): GoogleTest, GoogleMock and
# OpenCV's core and imgproc, 2.3 s of parsing in every test file, parsed once for all of them.
# softsight_test_pch compiles it with exactly the tests' flags and definitions (a precompiled
# header is only used by compiles that match it), and every test target reuses it.
# Test code is compiled at -O1 whatever the build type: the work a test does is the libraries'
# (at the build type's level); its own code is set-up and checks, and Release's -O3 made it
# compile 1.5x as long (a batch of the config tests: 23.5 s of CPU at -O3, 15.5 s at -O1).
function(softsight_test_definitions target)
  target_compile_definitions(${target} PRIVATE
    SOFTSIGHT_TEST_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    SOFTSIGHT_TEST_BINARY="${PROJECT_BINARY_DIR}/src/app/softsight")
  # (The instrumented tree compiles its tests at its own -O0: scripts/sanitizer/configure.sh.)
  if(NOT SOFTSIGHT_SANITIZE)
    target_compile_options(${target} PRIVATE $<$<CONFIG:Release,RelWithDebInfo>:-O1>)
  endif()
endfunction()
# The firmware's test is left out: its sketch's definitions (SOFTSIGHT_HOST_BUILD) differ.
function(softsight_reuse_test_pch target)
  if(NOT SOFTSIGHT_UNITY_BUILD OR target STREQUAL "softsight_firmware_test")
    return()
  endif()
  if(NOT TARGET softsight_test_pch)
    file(CONFIGURE OUTPUT ${PROJECT_BINARY_DIR}/test_pch.cc CONTENT "// softsight_test_pch\n")
    add_library(softsight_test_pch OBJECT ${PROJECT_BINARY_DIR}/test_pch.cc)
    target_link_libraries(softsight_test_pch PRIVATE ${OpenCV_LIBS} GTest::gtest GTest::gmock)
    softsight_test_definitions(softsight_test_pch)
    target_precompile_headers(softsight_test_pch PRIVATE
      <gtest/gtest.h> <gmock/gmock.h> <opencv2/core.hpp> <opencv2/imgproc.hpp>
      <string> <vector>)
  endif()
  target_precompile_headers(${target} REUSE_FROM softsight_test_pch)
endfunction()

# The tests' main(): GoogleTest's, plus SOFTSIGHT_TEST_EXCLUDE (src/core/test_main.cc).
function(softsight_test_main_library)
  if(NOT TARGET softsight_test_main)
    add_library(softsight_test_main STATIC ${PROJECT_SOURCE_DIR}/src/core/test_main.cc)
    target_link_libraries(softsight_test_main PUBLIC GTest::gtest)
  endif()
endfunction()

# Registers a test executable with ctest: one entry per test suite (or per 8 of its tests), all
# labelled `label`, found after the executable is built (cmake/discover_test_suites.cmake says
# why: one process per TEST cost more CPU in starting than most tests take).
function(softsight_discover_test_suites target label)
  set(base "${CMAKE_CURRENT_BINARY_DIR}/${target}")
  add_custom_command(
    TARGET ${target} POST_BUILD
    BYPRODUCTS "${base}_suites.cmake"
    COMMAND "${CMAKE_COMMAND}"
            -D "TEST_EXECUTABLE=$<TARGET_FILE:${target}>"
            -D "CTEST_FILE=${base}_suites.cmake"
            -D "LABEL=${label}"
            -D "WORKING_DIR=${CMAKE_CURRENT_BINARY_DIR}"
            -D "MAX_PER_ENTRY=8"
            -D "DISCOVERY_TIMEOUT=60"
            -P "${PROJECT_SOURCE_DIR}/cmake/discover_test_suites.cmake"
    VERBATIM)
  file(WRITE "${base}_include.cmake"
    "if(EXISTS \"${base}_suites.cmake\")\n"
    "  include(\"${base}_suites.cmake\")\n"
    "else()\n"
    "  add_test(${target}_NOT_BUILT ${target}_NOT_BUILT)\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${base}_include.cmake")
endfunction()

# softsight_add_test(<module> SOURCES ... DEPS ...)
# One GoogleTest executable per module (softsight_<module>_test), its tests registered with ctest
# by suite (softsight_discover_test_suites) with the ctest label <module> (`ctest -L io`).
# SOFTSIGHT_TEST_MODULES, when set, lists the modules whose tests are built (the instrumented
# tree builds only some: scripts/test-sanitize.sh).
function(softsight_add_test module)
  if(NOT SOFTSIGHT_BUILD_TESTS)
    return()
  endif()
  if(SOFTSIGHT_TEST_MODULES AND NOT module IN_LIST SOFTSIGHT_TEST_MODULES)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  set(target softsight_${module}_test)
  add_executable(${target} ${ARG_SOURCES})
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/src)
  # Test code may use any OpenCV module (writing fixtures, reading images), whatever its module links.
  softsight_test_main_library()
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} ${OpenCV_LIBS} GTest::gtest GTest::gmock
                                          softsight_test_main)
  # End-to-end tests find the program and the repository through these (env vars of the same
  # names override them).
  softsight_test_definitions(${target})
  softsight_use_unity_build(${target})
  softsight_reuse_test_pch(${target})
  softsight_discover_test_suites(${target} ${module})
endfunction()

# softsight_add_benchmark(<name> SOURCES ... DEPS ...)
# A Google Benchmark program (softsight_<name>_benchmark). Benchmarks never run as tests, and
# are not part of the default build (47 s of CPU that scripts/test.sh and CI do not need): the
# target softsight_benchmarks builds them all (scripts/bench.sh does).
function(softsight_add_benchmark name)
  if(NOT SOFTSIGHT_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  set(target softsight_${name}_benchmark)
  add_executable(${target} EXCLUDE_FROM_ALL ${ARG_SOURCES})
  if(NOT TARGET softsight_benchmarks)
    add_custom_target(softsight_benchmarks)
  endif()
  add_dependencies(softsight_benchmarks ${target})
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} ${OpenCV_LIBS} benchmark::benchmark
                                          benchmark::benchmark_main)
endfunction()

# softsight_check_public_headers()
# A public header is a promise: a library user has include/ (and OpenCV) on the path, never src/.
# Compiles every header in include/softsight/ on its own, in one translation unit per header, with
# exactly that include path, so a public header that includes a private one (or forgets one of
# softsight's headers it uses) fails the build. OpenCV's core and the standard headers the public
# headers use come precompiled: parsing them was ~1.9 s of each 2.6 s check (114 s of CPU for
# the 48 headers); a header that forgot one of those would still compile here. One more file
# initializes the public structs as a user would (designated initializers), under -Wextra.
function(softsight_check_public_headers)
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE ${PROJECT_SOURCE_DIR}/include
       ${PROJECT_SOURCE_DIR}/include/softsight/*.h)
  set(sources "")
  foreach(header ${headers})
    string(REPLACE "/" "__" name ${header})
    set(source ${PROJECT_BINARY_DIR}/public_headers/${name}.cc)
    file(CONFIGURE OUTPUT ${source} CONTENT "#include \"${header}\"\n")
    list(APPEND sources ${source})
  endforeach()
  # And a user's designated initializers of the public structs, under the same warnings
  # (-Wextra's missing-field-initializers): tests/api/designated_initializers.cc.
  list(APPEND sources ${PROJECT_SOURCE_DIR}/tests/api/designated_initializers.cc)
  # The umbrella header (softsight/softsight.h) includes every other public header: one left out
  # would be missing from `#include <softsight/softsight.h>` without any compile failing.
  file(READ ${PROJECT_SOURCE_DIR}/include/softsight/softsight.h umbrella)
  foreach(header ${headers})
    if(NOT header STREQUAL "softsight/softsight.h" AND NOT umbrella MATCHES "#include \"${header}\"")
      message(FATAL_ERROR "include/softsight/softsight.h does not include \"${header}\": add it")
    endif()
  endforeach()
  add_library(softsight_public_headers OBJECT ${sources})
  # version.h is generated (and installed beside the others).
  target_include_directories(softsight_public_headers PRIVATE ${PROJECT_SOURCE_DIR}/include
                                                              ${PROJECT_BINARY_DIR}/include)
  target_include_directories(softsight_public_headers SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_precompile_headers(softsight_public_headers PRIVATE
    <opencv2/core.hpp> <string> <optional> <vector> <cstdint> <memory> <functional> <chrono>)
endfunction()
