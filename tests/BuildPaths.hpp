// Where the build put things, for tests and benchmarks: the source tree, the test characters and
// the executables they run. The values live in one generated file (build_paths.cpp in the build
// tree, tests/BuildPaths.cmake), not in compile definitions, so that every other test source
// compiles to the same object in any clone and ccache reuses it (docs/testing.md "CI time").
//
// Each function returns a NUL-terminated absolute path that lives for the whole program. An
// environment variable of the function's DERMIS_ name (DERMIS_SOURCE_DIR, DERMIS_TEST_MODELS,
// DERMIS_SERVER_EXE, DERMIS_CLIENT_EXE, DERMIS_PATTERNGEN_EXE, DERMIS_CHARACTERGEN_EXE) replaces
// the built-in value when set and non-empty (a build tree moved to another machine). Nothing is
// checked: a path that does not exist fails where it is used.
#pragma once

namespace dermis::build {

const char* sourceDir();       ///< the clone's root (CMAKE_SOURCE_DIR)
const char* testModelsDir();   ///< tests/models or CMake's DERMIS_TEST_MODELS
const char* serverExe();       ///< dermis-server
const char* clientExe();       ///< dermis (client/)
const char* patterngenExe();   ///< dermis-patterngen
const char* charactergenExe(); ///< dermis-charactergen

} // namespace dermis::build
