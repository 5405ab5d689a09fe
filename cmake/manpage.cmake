# Makes the l6470emu(1) man page with help2man (cmake -P, run by the build): the program's
# --help and --version, each subcommand's --help as a SUBCOMMANDS section, and the sections
# of docs/l6470emu.h2m. Inputs: PROGRAM, HELP2MAN, INCLUDE, OUTPUT.
foreach(v PROGRAM HELP2MAN INCLUDE OUTPUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "manpage.cmake needs -D${v}=...")
  endif()
endforeach()

set(subcommands demo tables serve ctl run campaign coverage replay decode convert plot units)
set(section "[SUBCOMMANDS]\n")
foreach(sub ${subcommands})
  execute_process(COMMAND ${PROGRAM} ${sub} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${PROGRAM} ${sub} --help failed (${rc})")
  endif()
  string(REPLACE "\\" "\\e" help "${help}")   # roff escapes
  string(REGEX REPLACE "\n+$" "" help "${help}")
  string(APPEND section ".SS ${sub}\n.nf\n${help}\n.fi\n")
endforeach()

file(READ ${INCLUDE} sections)
get_filename_component(dir ${OUTPUT} DIRECTORY)
file(WRITE ${dir}/l6470emu-sections.h2m "${sections}\n${section}")
# help2man in a UTF-8 locale (in its default, C, it writes "??" for every non-ASCII character);
# then the characters become groff's own names (manpage_chars.cmake).
execute_process(COMMAND ${HELP2MAN} --locale=C.UTF-8 --no-info --section=1 --source=l6470emu
                        --name=register-level\ emulator\ of\ the\ ST\ L6470-family\ SPI\ motion\ engines
                        --include=${dir}/l6470emu-sections.h2m --output=${OUTPUT} ${PROGRAM}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "help2man failed (${rc})")
endif()
file(READ ${OUTPUT} page)
include(${CMAKE_CURRENT_LIST_DIR}/manpage_chars.cmake)
groff_characters(page)
file(WRITE ${OUTPUT} "${page}")
