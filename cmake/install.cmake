# Installation (GNUInstallDirs places): the model's static libraries with their public headers
# under include/l6470emu/, exported as l6470emu::core/spi/daisychain/board/linux and the
# firmware fronts l6470emu::firmware/arduino/stm32hal with l6470emu::ino (find_package) and
# described in l6470emu.pc (pkg-config); the preload library in lib/l6470emu/; the l6470emu
# program, its man page and the docs. The Python module installs itself (python/CMakeLists.txt).
# The locations themselves are set in cmake/install_dirs.cmake (included first).
include(CMakePackageConfigHelpers)

# Installed headers are reached as <l6470emu/core/chip.hpp> with -I<prefix>/include only: their
# own includes are rewritten to "l6470emu/core/x.hpp" when they are staged (install_headers.cmake),
# so no generic core/, spi/, linux/ folder lands on a consumer's include path.
set(layers core spi daisychain board linux)
foreach(layer ${layers})
  set_target_properties(l6470emu_${layer} PROPERTIES EXPORT_NAME ${layer})
endforeach()
target_include_directories(l6470emu_core INTERFACE
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_compile_features(l6470emu_core PUBLIC cxx_std_20)

# l6470emu::l6470emu: every layer at once.
add_library(l6470emu_all INTERFACE)
target_link_libraries(l6470emu_all INTERFACE l6470emu_linux)
set_target_properties(l6470emu_all PROPERTIES EXPORT_NAME l6470emu)

# The firmware fronts: their libraries, their headers (Arduino.h, SPI.h, stm32f4xx_hal.h, ...
# keep their own names in include/l6470emu/firmware/{arduino,stm32}), the sketch preprocessor
# (l6470emu::ino, in libexec) and the CMake functions that use them.
foreach(front firmware arduino stm32hal)
  set_target_properties(l6470emu_${front} PROPERTIES EXPORT_NAME ${front})
endforeach()
set_target_properties(l6470emu-ino PROPERTIES EXPORT_NAME ino)

install(TARGETS l6470emu_core l6470emu_spi l6470emu_daisychain l6470emu_board l6470emu_linux l6470emu_all
                l6470emu_firmware l6470emu_arduino l6470emu_stm32hal l6470emu-ino
  EXPORT l6470emuTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/l6470emu)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/l6470emuFirmware.cmake DESTINATION ${L6470EMU_INSTALL_CMAKEDIR})
# The headers of every layer and of the firmware fronts, staged with their includes rewritten
# (not the preload library's internals, *_internal.hpp, import_support.hpp, sketch_prep.hpp).
set(header_layers ${layers} firmware)
set(staged_include ${PROJECT_BINARY_DIR}/staged-include)
set(public_headers)
foreach(layer ${header_layers})
  file(GLOB_RECURSE h CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${layer}/*.hpp ${PROJECT_SOURCE_DIR}/${layer}/*.h)
  list(APPEND public_headers ${h})
endforeach()
add_custom_command(OUTPUT ${staged_include}/stamp
  COMMAND ${CMAKE_COMMAND} -DSRC=${PROJECT_SOURCE_DIR} -DOUT=${staged_include} "-DLAYERS=${header_layers}"
          -P ${CMAKE_CURRENT_LIST_DIR}/install_headers.cmake
  COMMAND ${CMAKE_COMMAND} -E touch ${staged_include}/stamp
  DEPENDS ${public_headers} ${CMAKE_CURRENT_LIST_DIR}/install_headers.cmake
  COMMENT "Staging the installed headers (includes spelled l6470emu/...)" VERBATIM)
add_custom_target(l6470emu_staged_headers ALL DEPENDS ${staged_include}/stamp)
install(DIRECTORY ${staged_include}/l6470emu DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT l6470emuTargets NAMESPACE l6470emu:: DESTINATION ${L6470EMU_INSTALL_CMAKEDIR})

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/l6470emuConfig.cmake.in
  ${PROJECT_BINARY_DIR}/l6470emuConfig.cmake
  INSTALL_DESTINATION ${L6470EMU_INSTALL_CMAKEDIR}
  PATH_VARS L6470EMU_INSTALL_PRELOADDIR CMAKE_INSTALL_BINDIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/l6470emuConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)  # 0.x: a minor version may change the API
install(FILES ${PROJECT_BINARY_DIR}/l6470emuConfig.cmake ${PROJECT_BINARY_DIR}/l6470emuConfigVersion.cmake
  DESTINATION ${L6470EMU_INSTALL_CMAKEDIR})

# pkg-config: relocatable (prefix found from the .pc file's own place).
file(RELATIVE_PATH L6470EMU_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${CMAKE_CURRENT_LIST_DIR}/l6470emu.pc.in ${PROJECT_BINARY_DIR}/l6470emu.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/l6470emu.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# The preload library (LD_PRELOAD only: no headers, not linked against) and the program.
install(TARGETS l6470emu-preload LIBRARY DESTINATION ${L6470EMU_INSTALL_PRELOADDIR})
install(TARGETS l6470emu RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The man page, made from the program's own --help by help2man (Debian's help2man).
find_program(L6470EMU_HELP2MAN help2man)
if(L6470EMU_HELP2MAN)
  add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/l6470emu.1
    COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:l6470emu> -DHELP2MAN=${L6470EMU_HELP2MAN}
            -DINCLUDE=${PROJECT_SOURCE_DIR}/docs/l6470emu.h2m -DOUTPUT=${PROJECT_BINARY_DIR}/l6470emu.1
            -P ${CMAKE_CURRENT_LIST_DIR}/manpage.cmake
    DEPENDS l6470emu ${PROJECT_SOURCE_DIR}/docs/l6470emu.h2m ${CMAKE_CURRENT_LIST_DIR}/manpage.cmake
            ${CMAKE_CURRENT_LIST_DIR}/manpage_chars.cmake
    COMMENT "Generating the l6470emu(1) man page")
  # Installed compressed, as Debian's policy asks (man reads it the same everywhere).
  add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/l6470emu.1.gz
    COMMAND gzip -9nc ${PROJECT_BINARY_DIR}/l6470emu.1 > ${PROJECT_BINARY_DIR}/l6470emu.1.gz
    DEPENDS ${PROJECT_BINARY_DIR}/l6470emu.1 VERBATIM)
  add_custom_target(l6470emu_manpage ALL DEPENDS ${PROJECT_BINARY_DIR}/l6470emu.1 ${PROJECT_BINARY_DIR}/l6470emu.1.gz)
  if(L6470EMU_TESTS)  # the page in the C locale: ASCII stand-ins, never "??" (skipped without man-db)
    add_test(NAME manpage COMMAND sh ${PROJECT_SOURCE_DIR}/tests/tools/manpage_test.sh ${PROJECT_BINARY_DIR}/l6470emu.1)
    set_tests_properties(manpage PROPERTIES LABELS tools SKIP_RETURN_CODE 77)
  endif()
  install(FILES ${PROJECT_BINARY_DIR}/l6470emu.1.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
  # A page per subcommand, l6470emu-run(1) and so on, each from its own --help.
  set(L6470EMU_SUBCOMMAND_PAGES demo tables serve ctl run campaign campaign-merge coverage-report coverage-merge
      replay decode convert plot units report)
  set(sub_pages "")
  foreach(sub ${L6470EMU_SUBCOMMAND_PAGES})
    set(page ${PROJECT_BINARY_DIR}/man/l6470emu-${sub}.1)
    add_custom_command(OUTPUT ${page}.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man
      COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:l6470emu> -DHELP2MAN=${L6470EMU_HELP2MAN} -DSUB=${sub}
              -DVERSION=${PROJECT_VERSION} -DOUTPUT=${page} -P ${CMAKE_CURRENT_LIST_DIR}/manpage_sub.cmake
      COMMAND gzip -9nf ${page}
      DEPENDS l6470emu ${CMAKE_CURRENT_LIST_DIR}/manpage_sub.cmake ${CMAKE_CURRENT_LIST_DIR}/manpage_sub.h2m
              ${CMAKE_CURRENT_LIST_DIR}/manpage_chars.cmake
      COMMENT "Generating the l6470emu-${sub}(1) man page" VERBATIM)
    list(APPEND sub_pages ${page}.gz)
  endforeach()
  add_custom_target(l6470emu_subcommand_manpages ALL DEPENDS ${sub_pages})
  install(FILES ${sub_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
  if(L6470EMU_TESTS)  # every subcommand has its page, and run's lists its options
    add_test(NAME subcommand_manpages COMMAND sh ${PROJECT_SOURCE_DIR}/tests/tools/subcommand_manpages_test.sh
             ${PROJECT_BINARY_DIR}/man ${L6470EMU_SUBCOMMAND_PAGES})
    set_tests_properties(subcommand_manpages PROPERTIES LABELS tools SKIP_RETURN_CODE 77)
  endif()
else()
  message(STATUS "l6470emu: help2man not found: no man page (apt-get install help2man)")
endif()

install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The copyright file (Debian's machine-readable format) and, for the .deb (a native package),
# a Debian changelog entry for this version, compressed as the policy asks.
install(FILES ${CMAKE_CURRENT_LIST_DIR}/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})
set(L6470EMU_PACKAGE_CONTACT "l6470emu maintainers <maintainers@l6470emu.invalid>" CACHE STRING
    "Maintainer field of the .deb and its changelog")
string(TIMESTAMP L6470EMU_CHANGELOG_DATE "%a, %d %b %Y %H:%M:%S +0000" UTC)  # SOURCE_DATE_EPOCH if set
file(WRITE ${PROJECT_BINARY_DIR}/changelog
"l6470emu (${PROJECT_VERSION}) unstable; urgency=medium

  * Built with CPack from the l6470emu source tree; the project's history is
    its git log.

 -- ${L6470EMU_PACKAGE_CONTACT}  ${L6470EMU_CHANGELOG_DATE}
")
add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/changelog.gz
  COMMAND gzip -9nc ${PROJECT_BINARY_DIR}/changelog > ${PROJECT_BINARY_DIR}/changelog.gz
  DEPENDS ${PROJECT_BINARY_DIR}/changelog VERBATIM)
add_custom_target(l6470emu_changelog ALL DEPENDS ${PROJECT_BINARY_DIR}/changelog.gz)
install(FILES ${PROJECT_BINARY_DIR}/changelog.gz DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} FILES_MATCHING PATTERN "*.md")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples DESTINATION ${CMAKE_INSTALL_DOCDIR}
  PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)
