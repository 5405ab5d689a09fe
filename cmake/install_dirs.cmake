# Install locations, defined before any subdirectory reads them (python/ bakes the preload's
# and the program's installed paths into its install script at configure time, so these must
# be set on the very first configure, not only once the cache holds them).
include(GNUInstallDirs)
set(L6470EMU_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/l6470emu CACHE STRING
    "Where l6470emuConfig.cmake goes, relative to the prefix")
set(L6470EMU_INSTALL_PRELOADDIR ${CMAKE_INSTALL_LIBDIR}/l6470emu CACHE STRING
    "Where libl6470emu-preload.so goes, relative to the prefix")
