# The man pages, generated from the program's own --help by help2man (cmake/package.cmake runs this
# after the program and its plugins are built): softsight(1), and softsight-<command>(1) for each
# subcommand `softsight --help` lists (as git-commit(1) is for `git commit`), gzipped as Debian
# installs them.
#   cmake -DPROGRAM=build/src/app/softsight -DHELP2MAN=/usr/bin/help2man -DOUT=build/man -P cmake/man_pages.cmake
cmake_minimum_required(VERSION 3.22)
get_filename_component(program_dir "${PROGRAM}" DIRECTORY)
get_filename_component(program_name "${PROGRAM}" NAME)
# Run as `softsight` from PATH, so the usage lines name the program, not its build folder.
set(run ${CMAKE_COMMAND} -E env "PATH=${program_dir}:$ENV{PATH}")

execute_process(COMMAND ${run} ${program_name} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${program_name} --help failed (${rc})")
endif()
string(REGEX REPLACE ".*\nSubcommands:\n" "" commands_text "${help}")
string(REPLACE "\n" ";" command_lines "${commands_text}")
set(commands "")
foreach(line IN LISTS command_lines)
  if(line MATCHES "^  ([a-z][a-z-]*)  +(.+)$")
    list(APPEND commands ${CMAKE_MATCH_1})
    string(STRIP "${CMAKE_MATCH_2}" text)
    # "Render the built-in demo scene, ..." -> "render the built-in demo scene, ..."
    string(SUBSTRING "${text}" 0 1 first)
    string(SUBSTRING "${text}" 1 -1 rest)
    string(TOLOWER "${first}" first)
    set(summary_${CMAKE_MATCH_1} "${first}${rest}")
  endif()
endforeach()
list(LENGTH commands count)
if(count EQUAL 0)
  message(FATAL_ERROR "no subcommands in `${program_name} --help`")
endif()

file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
set(see_also "")
foreach(command IN LISTS commands)
  string(APPEND see_also ".BR ${program_name}-${command} (1)\n")
endforeach()
file(WRITE "${OUT}/see_also.h2m" "[SEE ALSO]\n${see_also}")
file(WRITE "${OUT}/see_main.h2m" "[SEE ALSO]\n.BR ${program_name} (1)\n")

function(help2man page name help_option see_also)
  execute_process(
    COMMAND ${run} ${HELP2MAN} --no-info --no-discard-stderr --section=1
            "--help-option=${help_option}" --version-option=--version "--name=${name}"
            --include=${OUT}/${see_also} --output=${OUT}/${page}.1 ${program_name}
    RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "help2man for ${page} failed: ${err}")
  endif()
endfunction()

help2man(${program_name} "measure soft robots with a camera" --help see_also.h2m)
foreach(command IN LISTS commands)
  set(page ${program_name}-${command})
  help2man(${page} "${summary_${command}}" "${command} --help" see_main.h2m)
  # help2man names the page after the program: make it the command's own.
  file(READ "${OUT}/${page}.1" text)
  string(TOUPPER "${page}" title)
  string(TOUPPER "${program_name}" program_title)
  string(REPLACE ".TH ${program_title} " ".TH ${title} " text "${text}")
  string(REPLACE "\n${program_name} \\- " "\n${page} \\- " text "${text}")
  file(WRITE "${OUT}/${page}.1" "${text}")
endforeach()
file(REMOVE "${OUT}/see_also.h2m" "${OUT}/see_main.h2m")

# gzip -9n: no name or time stamp in the archive, the same bytes from the same page.
file(GLOB pages "${OUT}/*.1")
foreach(page IN LISTS pages)
  execute_process(COMMAND gzip -9nf "${page}" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "gzip ${page} failed")
  endif()
endforeach()
list(LENGTH pages count)
message(STATUS "man pages: ${count} in ${OUT}")
