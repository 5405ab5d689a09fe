# The layering rule, checked on the sources (ctest `layer_includes`, labels board and core):
# each layer includes only its own and lower layers (core -> spi -> daisychain -> board ->
# linux), and core/ and board/ include no header that reaches the OS (threads, file
# descriptors, clocks, signals, dynamic loading). Usage: cmake -DSOURCE_DIR=... -P check_layer_includes.cmake
cmake_minimum_required(VERSION 3.25)
set(order core spi daisychain board linux)
set(os_free core board)
set(project_dirs core spi daisychain board linux tools python firmware)
set(os_headers "unistd\\.h|fcntl\\.h|poll\\.h|dlfcn\\.h|pthread\\.h|signal\\.h|csignal|time\\.h|ctime|chrono|thread|mutex|shared_mutex|condition_variable|future|semaphore|stop_token|barrier|latch|sys/[^>]*|linux/[^>]*|asm/[^>]*")

set(problems "")
set(allowed "")
foreach(layer ${order})
  list(APPEND allowed ${layer})
  file(GLOB_RECURSE files ${SOURCE_DIR}/${layer}/*.hpp ${SOURCE_DIR}/${layer}/*.cpp ${SOURCE_DIR}/${layer}/*.h
       ${SOURCE_DIR}/${layer}/*.c)
  foreach(f ${files})
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
    file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line ${lines})
      if(line MATCHES "#[ \t]*include[ \t]*\"([a-z_]+)/")
        set(dir ${CMAKE_MATCH_1})
        if(dir IN_LIST project_dirs AND NOT dir IN_LIST allowed)
          string(APPEND problems "${rel}: ${line} (${layer}/ may not include ${dir}/)\n")
        endif()
      endif()
      if(layer IN_LIST os_free AND line MATCHES "#[ \t]*include[ \t]*<(${os_headers})>")
        string(APPEND problems "${rel}: ${line} (${layer}/ knows no OS: no threads, file descriptors or clocks)\n")
      endif()
    endforeach()
  endforeach()
endforeach()

if(problems)
  message(FATAL_ERROR "layering broken:\n${problems}")
endif()
message(STATUS "layering: core -> spi -> daisychain -> board -> linux hold; core/ and board/ include no OS header")
