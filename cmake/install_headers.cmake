# cmake -P: copies the public headers of the layers into OUT/l6470emu/<layer>/ with their own
# includes spelled "l6470emu/<layer>/x.hpp", so that a consumer needs -I<prefix>/include only
# and its own core/, spi/, ... folders never meet ours. Writes a file only when it changed, and
# removes a staged header whose source is gone (a header moved to another layer).
# Variables: SRC (source tree), OUT (the staging include directory), LAYERS (;-list).
cmake_policy(SET CMP0057 NEW)  # if(IN_LIST)
set(staged)
set(layer_re "(core|spi|daisychain|board|linux|firmware)/")
foreach(layer ${LAYERS})
  file(GLOB_RECURSE headers RELATIVE ${SRC} ${SRC}/${layer}/*.hpp ${SRC}/${layer}/*.h)
  foreach(h ${headers})
    if(h MATCHES "_internal\\.hpp$" OR h MATCHES "^linux/preload/" OR h MATCHES "import_support\\.hpp$"
       OR h MATCHES "sketch_prep\\.hpp$")
      continue()
    endif()
    file(READ ${SRC}/${h} text)
    string(REGEX REPLACE "#include \"${layer_re}" "#include \"l6470emu/\\1/" text "${text}")
    set(dest ${OUT}/l6470emu/${h})
    list(APPEND staged ${dest})
    set(old "")
    if(EXISTS ${dest})
      file(READ ${dest} old)
    endif()
    if(NOT old STREQUAL text)
      file(WRITE ${dest} "${text}")
    endif()
  endforeach()
endforeach()
file(GLOB_RECURSE present ${OUT}/l6470emu/*.hpp ${OUT}/l6470emu/*.h)
foreach(f ${present})
  if(NOT f IN_LIST staged)
    file(REMOVE ${f})
  endif()
endforeach()
