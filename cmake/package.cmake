# Packaging: `cpack -G DEB` in a build directory makes l6470emu_VERSION_ARCH.deb for Debian
# bookworm from what `cmake --install` installs, into /usr. Run-time dependencies come from
# dpkg-shlibdeps (libc6, libstdc++6, libgcc-s1) plus the Python the module was built for;
# py-spidev, libgpiod and sigrok-cli are what users' programs use, so they are only suggested.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME l6470emu)
set(CPACK_PACKAGE_VENDOR "l6470emu")
set(CPACK_PACKAGE_CONTACT "${L6470EMU_PACKAGE_CONTACT}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "register-level emulator of the ST L6470-family SPI motion engines")
set(CPACK_PACKAGE_DESCRIPTION
    "Emulates the L6470, L6472, L6480, L6482 and powerSTEP01 byte-exactly on SPI,\n\
in daisy chains, in virtual time: C++ libraries and headers (CMake package and\n\
pkg-config), an LD_PRELOAD library that gives unmodified programs\n\
/dev/spidevB.C and /dev/gpiochipN, the l6470emu program (replay, decode,\n\
convert traces; serve), and the l6470emu Python module with its pytest plugin.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_STRIP_FILES ON)  # the program and the preload library
find_program(CPACK_STRIP_PROGRAM strip)
set(CPACK_PRE_BUILD_SCRIPTS ${CMAKE_CURRENT_LIST_DIR}/strip_static_libraries.cmake)  # debug info only
set(CPACK_DEBIAN_PACKAGE_SECTION devel)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3-pytest, python3-spidev, python3-libgpiod, python3-numpy, python3-matplotlib, sigrok-cli, umockdev")
if(L6470EMU_PYTHON_VERSION)
  # The module is built for one CPython (its file name carries the ABI tag).
  string(REPLACE "." ";" pv "${L6470EMU_PYTHON_VERSION}")
  list(GET pv 0 pv_major)
  list(GET pv 1 pv_minor)
  math(EXPR pv_next "${pv_minor} + 1")
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3 (>= ${pv_major}.${pv_minor}), python3 (<< ${pv_major}.${pv_next})")
endif()
include(CPack)
