# The layering rule, checked on the sources (ctest `layer_includes`, labels board, core and
# firmware): each layer includes only its own and lower layers (core -> spi -> daisychain ->
# board, and on the board two fronts side by side: linux and firmware, neither including the
# other), and core/, board/ and firmware/ include no header that reaches the OS (threads, file
# descriptors, clocks, signals, dynamic loading).
# Usage: cmake -DSOURCE_DIR=... -P check_layer_includes.cmake
cmake_minimum_required(VERSION 3.25)
set(layers core spi daisychain board linux firmware)
set(allowed_core core)
set(allowed_spi core spi)
set(allowed_daisychain core spi daisychain)
set(allowed_board core spi daisychain board)
set(allowed_linux core spi daisychain board linux)
set(allowed_firmware core spi daisychain board firmware)
set(os_free core board firmware)
set(project_dirs core spi daisychain board linux tools python firmware)
set(os_headers "unistd\\.h|fcntl\\.h|poll\\.h|dlfcn\\.h|pthread\\.h|signal\\.h|csignal|time\\.h|ctime|chrono|thread|mutex|shared_mutex|condition_variable|future|semaphore|stop_token|barrier|latch|sys/[^>]*|linux/[^>]*|asm/[^>]*")

set(problems "")
foreach(layer ${layers})
  file(GLOB_RECURSE files ${SOURCE_DIR}/${layer}/*.hpp ${SOURCE_DIR}/${layer}/*.cpp ${SOURCE_DIR}/${layer}/*.h
       ${SOURCE_DIR}/${layer}/*.c)
  foreach(f ${files})
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
    file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line ${lines})
      if(line MATCHES "#[ \t]*include[ \t]*[\"<]([a-z_]+)/")
        set(dir ${CMAKE_MATCH_1})
        if(dir IN_LIST project_dirs AND NOT dir IN_LIST allowed_${layer})
          string(APPEND problems "${rel}: ${line} (${layer}/ may not include ${dir}/)\n")
        endif()
      endif()
      if(layer IN_LIST os_free AND line MATCHES "#[ \t]*include[ \t]*[<\"](${os_headers})[>\"]")
        string(APPEND problems "${rel}: ${line} (${layer}/ knows no OS: no threads, file descriptors or clocks)\n")
      endif()
    endforeach()
  endforeach()
endforeach()

if(problems)
  message(FATAL_ERROR "layering broken:\n${problems}")
endif()
message(STATUS "layering: core -> spi -> daisychain -> board -> linux | firmware hold; core/, board/ and firmware/ "
               "include no OS header")
