# The documentation site (docs/build_site.py: Sphinx with MyST, autodoc and Breathe, from Debian's
# python3-sphinx, python3-myst-parser, python3-breathe and doxygen). Not built by default:
#   cmake --build BUILD --target l6470emu_docs     -> BUILD/docs/html/index.html
# ctest's `docs` test (label docs) builds it the same way and opens it in headless Chromium
# (tests/docs/docs_test.py); scripts/quickstart.sh test runs it as a stage of its own. The site
# documents the built program and Python module, so it needs both (not in a sanitizer build,
# which has no module). An install made after the site was built carries it in
# share/doc/l6470emu/html.
if(NOT TARGET l6470emu_python)
  message(STATUS "l6470emu: no documentation site target in this build (it documents the Python module, "
                 "which this build does not make)")
  return()
endif()

# One process: on the 2-core machine a clean build took 30-32 s with -j 1 and 40-43 s with -j 2
# (at load averages of 4-21, other builds running).
set(L6470EMU_DOCS_JOBS 1 CACHE STRING "Sphinx processes building the documentation site")
add_custom_target(l6470emu_docs
  COMMAND ${Python_EXECUTABLE} ${PROJECT_SOURCE_DIR}/docs/build_site.py --source ${PROJECT_SOURCE_DIR}
          --build ${PROJECT_BINARY_DIR} --jobs ${L6470EMU_DOCS_JOBS}
  USES_TERMINAL
  COMMENT "Building the documentation site (docs/build_site.py) into ${PROJECT_BINARY_DIR}/docs/html")
add_dependencies(l6470emu_docs l6470emu l6470emu_python)

if(L6470EMU_TESTS)
  # Skipped (77), with the reason, when a package it needs is missing.
  add_test(NAME docs COMMAND ${Python_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tests/docs/docs_test.py
           --source ${PROJECT_SOURCE_DIR} --build ${PROJECT_BINARY_DIR} --jobs ${L6470EMU_DOCS_JOBS})
  set_tests_properties(docs PROPERTIES LABELS docs SKIP_RETURN_CODE 77 TIMEOUT 600 COST 36
                       ENVIRONMENT "PYTHONDONTWRITEBYTECODE=1")
endif()

# The built site, when there is one (a .buildinfo is Sphinx's own bookkeeping), and with it the
# lintian override that says why its search scripts are its own (cmake/l6470emu.lintian-overrides).
install(DIRECTORY ${PROJECT_BINARY_DIR}/docs/html/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/html OPTIONAL
        PATTERN ".buildinfo" EXCLUDE)
install(CODE "
  if(EXISTS \"${PROJECT_BINARY_DIR}/docs/html/index.html\")
    file(INSTALL \"${PROJECT_SOURCE_DIR}/cmake/l6470emu.lintian-overrides\"
         DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATAROOTDIR}/lintian/overrides\" RENAME l6470emu)
  endif()")
