# Writes DST from the template SRC with the project version and the git
# commit of SOURCE_DIR (or COMMIT where given), touching DST only when its
# text changes: run at every build, so that a build records the commit it
# was made from, not the one of its last configure.
if(COMMIT)
  set(ACCRETION_GIT "${COMMIT}")
else()
  execute_process(COMMAND git describe --always --dirty --abbrev=10
                  WORKING_DIRECTORY ${SOURCE_DIR}
                  OUTPUT_VARIABLE ACCRETION_GIT OUTPUT_STRIP_TRAILING_WHITESPACE
                  ERROR_QUIET)
endif()
if(NOT ACCRETION_GIT)
  set(ACCRETION_GIT "unknown")
endif()
set(PROJECT_VERSION "${VERSION}")
configure_file(${SRC} ${DST} @ONLY)
