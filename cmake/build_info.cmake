# Writes the program's build record (version and the source tree's commit) to OUT, only when it
# changed, so that a build after a commit recompiles one file. Run at every build by the
# spinesim_build_info_record target (common/CMakeLists.txt). A tree that is not a git checkout
# records the commit "unknown"; one with uncommitted changes to tracked files records
# "<sha>-dirty".
set(commit "unknown")
find_program(GIT git)
if(GIT)
  execute_process(COMMAND ${GIT} -C ${SRC} rev-parse HEAD OUTPUT_VARIABLE sha
                  RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(rc EQUAL 0 AND sha)
    set(commit ${sha})
    execute_process(COMMAND ${GIT} -C ${SRC} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes RESULT_VARIABLE rc2 ERROR_QUIET)
    if(rc2 EQUAL 0 AND NOT changes STREQUAL "")
      set(commit "${commit}-dirty")
    endif()
  endif()
endif()
set(text "// Generated at build time by cmake/build_info.cmake: do not edit.
#include \"spinesim/common/build_info.hpp\"

namespace spinesim {
const char* build_version() { return \"${VERSION}\"; }
const char* build_commit() { return \"${commit}\"; }
}  // namespace spinesim
")
set(old "")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
