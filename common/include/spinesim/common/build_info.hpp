// What this program is: its version and the commit of the source it was built from, recorded at
// build time (cmake/build_info.cmake). A build from a tree with uncommitted changes says
// "<sha>-dirty"; one outside a git checkout says "unknown".
#pragma once

namespace spinesim {

const char* build_version();  ///< e.g. "0.1.0" (the project's version in CMakeLists.txt)
const char* build_commit();   ///< 40 hex digits, optionally "-dirty", or "unknown"

}  // namespace spinesim
