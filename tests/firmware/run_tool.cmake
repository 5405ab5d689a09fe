# The l6470emu program run on a firmware program (`run`, `campaign`): COMMAND (a list: the tool,
# its arguments, --, the program) runs in WORK (made empty first); it must exit with STATUS, its
# standard error must contain every string of STDERR_HAS and none of STDERR_LACKS, its standard
# output every string of STDOUT_HAS, and the file FILE (in WORK), when given, every string of
# FILE_HAS and none of FILE_LACKS. Its standard input is empty (/dev/null). Lists are joined by | (strings with | in them cannot be checked).
# Usage: cmake "-DCOMMAND=l6470emu|run|--chain|L6470|--|prog" -DSTATUS=0 -DWORK=dir "-DSTDERR_HAS=a|b" -P run_tool.cmake
foreach(v COMMAND STDERR_HAS STDERR_LACKS STDOUT_HAS STDOUT_LACKS FILE_HAS FILE_LACKS)
  string(REPLACE "|" ";" ${v} "${${v}}")
endforeach()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
execute_process(COMMAND ${COMMAND} WORKING_DIRECTORY "${WORK}" INPUT_FILE /dev/null OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
include(${CMAKE_CURRENT_LIST_DIR}/expect_output.cmake)
expect_output("${rc}" "${out}" "${err}")
set(shown "exit ${rc}\n--- stdout:\n${out}--- stderr:\n${err}")
if(FILE)
  file(READ "${WORK}/${FILE}" text)
  foreach(s IN LISTS FILE_HAS)
    string(FIND "${text}" "${s}" at)
    if(at LESS 0)
      message(FATAL_ERROR "${FILE} lacks '${s}': ${shown}\n--- ${FILE}:\n${text}")
    endif()
  endforeach()
  foreach(s IN LISTS FILE_LACKS)
    string(FIND "${text}" "${s}" at)
    if(NOT at LESS 0)
      message(FATAL_ERROR "${FILE} has '${s}': ${shown}\n--- ${FILE}:\n${text}")
    endif()
  endforeach()
endif()
message(STATUS "exit ${rc} as expected; stdout:\n${out}stderr:\n${err}")
