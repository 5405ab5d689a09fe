# CPack pre-build script: strips the debugging information from the staged static libraries
# (as Debian's dh_strip does for -dev packages); their symbols stay, so they still link.
file(GLOB_RECURSE archives "${CPACK_TEMPORARY_INSTALL_DIRECTORY}/*.a")
foreach(a ${archives})
  execute_process(COMMAND ${CPACK_STRIP_PROGRAM} --strip-debug ${a} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "strip --strip-debug ${a} failed (${rc})")
  endif()
endforeach()
