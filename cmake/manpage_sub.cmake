# Makes the man page of one subcommand, l6470emu-SUB(1), with help2man (cmake -P, run by the
# build): `l6470emu SUB --help` is the page (its first line the NAME), from the same source as
# the program's own help, so the two cannot drift. Inputs: PROGRAM, HELP2MAN, SUB (words may be
# joined by '-': "coverage-report"), VERSION, OUTPUT.
foreach(v PROGRAM HELP2MAN SUB VERSION OUTPUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "manpage_sub.cmake needs -D${v}=...")
  endif()
endforeach()
string(REPLACE "-" ";" words "${SUB}")
execute_process(COMMAND ${PROGRAM} ${words} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} ${words} --help failed (${rc})")
endif()
string(REGEX REPLACE "\n.*" "" name "${help}")
# help2man runs a program: a two-line script that is `l6470emu SUB`.
get_filename_component(dir ${OUTPUT} DIRECTORY)
set(wrapper ${dir}/l6470emu-${SUB})
string(REPLACE ";" " " words_text "${words}")
file(WRITE ${wrapper} "#!/bin/sh\nexec '${PROGRAM}' ${words_text} \"$@\"\n")
file(CHMOD ${wrapper} PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
execute_process(COMMAND ${HELP2MAN} --locale=C.UTF-8 --no-info --section=1 --source=l6470emu
                        "--version-string=l6470emu-${SUB} ${VERSION}" "--name=${name}"
                        "--include=${CMAKE_CURRENT_LIST_DIR}/manpage_sub.h2m" --output=${OUTPUT} ${wrapper}
                RESULT_VARIABLE rc)
file(REMOVE ${wrapper})
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "help2man failed for ${SUB} (${rc})")
endif()
# As the main page: the characters groff names (manpage_chars.cmake).
file(READ ${OUTPUT} page)
include(${CMAKE_CURRENT_LIST_DIR}/manpage_chars.cmake)
groff_characters(page)
file(WRITE ${OUTPUT} "${page}")
