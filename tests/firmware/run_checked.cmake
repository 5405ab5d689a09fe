# A firmware program run under the driver sanitizer: PROGRAM runs with the environment ENV (a
# list of NAME=VALUE); it must exit with STATUS, its standard error must contain every string of
# STDERR_HAS (a list) and none of STDERR_LACKS, its standard output every string of STDOUT_HAS
# and none of STDOUT_LACKS. INPUT, when given, is the file its standard input reads (else none:
# /dev/null).
# Lists are joined by | (strings with | in them cannot be checked).
# Usage: cmake -DPROGRAM=... -DSTATUS=86 "-DENV=L6470EMU_CHECK=error" "-DSTDERR_HAS=a|b" -P run_checked.cmake
foreach(v ENV STDERR_HAS STDERR_LACKS STDOUT_HAS STDOUT_LACKS)
  string(REPLACE "|" ";" ${v} "${${v}}")
endforeach()
if(NOT INPUT)
  set(INPUT /dev/null)
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env ${ENV} "${PROGRAM}" INPUT_FILE "${INPUT}" OUTPUT_VARIABLE out
                ERROR_VARIABLE err RESULT_VARIABLE rc)
include(${CMAKE_CURRENT_LIST_DIR}/expect_output.cmake)
expect_output("${rc}" "${out}" "${err}")
message(STATUS "exit ${rc} as expected; stderr:\n${err}")
