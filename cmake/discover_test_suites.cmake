# Run after a test executable is built (cmake -P, from softsight_add_test): lists its tests
# (--gtest_list_tests) and writes one ctest entry per test suite, so ctest starts the executable
# once per suite instead of once per TEST. Starting a test executable costs ~0.3 s of CPU (the
# dynamic loader resolving OpenCV's ~250 libraries: FFmpeg, GDAL, Qt, ...), while most of our
# tests take milliseconds: the config module's 58 tests took 19 s of CPU one process each and
# 0.5 s in one process. A suite of more than MAX_PER_ENTRY tests is split into entries of that
# many (named "Suite.part1of3", ...) so the long suites still run side by side.
#
# In:  TEST_EXECUTABLE, CTEST_FILE (written), LABEL (ctest label of every entry),
#      WORKING_DIR, MAX_PER_ENTRY, DISCOVERY_TIMEOUT (s).
# A failing entry's output names the failing tests; run one alone with
# `<executable> --gtest_filter=Suite.Test`. Disabled tests (DISABLED_) are left to GoogleTest,
# which does not run them.

execute_process(
  COMMAND "${TEST_EXECUTABLE}" --gtest_list_tests
  WORKING_DIRECTORY "${WORKING_DIR}"
  TIMEOUT ${DISCOVERY_TIMEOUT}
  OUTPUT_VARIABLE listing
  RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "${TEST_EXECUTABLE} --gtest_list_tests failed (${result}):\n${listing}")
endif()

# The listing: "Suite.\n  Test\n  Test  # GetParam() = ...\nOther/Suite.\n  Test/0\n".
string(REPLACE ";" "\\;" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(suites "")
set(suite "")
foreach(line IN LISTS lines)
  string(REGEX REPLACE " *#.*$" "" line "${line}")
  if(line STREQUAL "")
    continue()
  endif()
  if(line MATCHES "^  (.+)$")
    set(test "${CMAKE_MATCH_1}")
    if(NOT test MATCHES "^DISABLED_" AND NOT suite MATCHES "^DISABLED_")
      list(APPEND "tests_${suite}" "${test}")
    endif()
  elseif(line MATCHES "^([^ ].*)\\.$")
    set(suite "${CMAKE_MATCH_1}")
    list(APPEND suites "${suite}")
  endif()
endforeach()

set(content "")
string(APPEND content "# Written by cmake/discover_test_suites.cmake from ${TEST_EXECUTABLE}\n")
foreach(suite IN LISTS suites)
  set(tests ${tests_${suite}})
  list(LENGTH tests count)
  if(count EQUAL 0)
    continue()
  endif()
  if(count LESS_EQUAL MAX_PER_ENTRY)
    set(names "${suite}")
    set(filters "${suite}.*")
  else()
    math(EXPR parts "(${count} + ${MAX_PER_ENTRY} - 1) / ${MAX_PER_ENTRY}")
    set(names "")
    set(filters "")
    foreach(part RANGE 1 ${parts})
      math(EXPR first "(${part} - 1) * ${MAX_PER_ENTRY}")
      math(EXPR last "${first} + ${MAX_PER_ENTRY} - 1")
      if(last GREATER_EQUAL count)
        math(EXPR last "${count} - 1")
      endif()
      set(filter "")
      foreach(i RANGE ${first} ${last})
        list(GET tests ${i} test)
        string(APPEND filter "${suite}.${test}:")
      endforeach()
      string(REGEX REPLACE ":$" "" filter "${filter}")
      list(APPEND names "${suite}.part${part}of${parts}")
      list(APPEND filters "${filter}")
    endforeach()
  endif()
  foreach(name filter IN ZIP_LISTS names filters)
    string(APPEND content
      "add_test([=[${name}]=] [==[${TEST_EXECUTABLE}]==] [==[--gtest_filter=${filter}]==])\n"
      "set_tests_properties([=[${name}]=] PROPERTIES LABELS [==[${LABEL}]==] "
      "WORKING_DIRECTORY [==[${WORKING_DIR}]==])\n")
  endforeach()
endforeach()
file(WRITE "${CTEST_FILE}" "${content}")
