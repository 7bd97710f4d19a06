# Writes OUT (version.hpp) from IN with the project version plus `git describe`, at every build
# rather than at configure time, so a binary never reports a commit it was not built from. The
# file is rewritten only when the string changes, so an unchanged tree recompiles nothing.
execute_process(COMMAND git describe --always --dirty --abbrev=12
                WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE BEDFORGE_GIT OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(BEDFORGE_GIT)
  set(BEDFORGE_VERSION_STRING "${PROJECT_VERSION}+${BEDFORGE_GIT}")
else()
  set(BEDFORGE_VERSION_STRING "${PROJECT_VERSION}")
endif()
configure_file(${IN} ${OUT} @ONLY)
