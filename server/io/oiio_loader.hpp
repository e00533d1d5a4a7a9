// Dermis io shell (internal) — loads libdermis_oiio.so (oiio_module.hpp) with dlopen on first
// use, so that no executable links OpenImageIO.
//
// Where the module is looked for, in order: $DERMIS_OIIO_MODULE when set (and then only there);
// the folder of the running executable (/proc/self/exe); the folder of the library that holds
// this code (dladdr; the same unless Dermis is itself a shared library); the build tree's module
// (a path configured by CMake, so tests and benchmarks in build/ subfolders find it).
//
// Thread-safe; the first successful load is kept for the life of the process (never dlclose'd).
// A failed load is retried on the next call. Fails with ErrorCode::Unavailable, naming the module
// file, every path tried and dlerror()'s reason.
#pragma once

#include "core/result.hpp"
#include "io/oiio_module.hpp"

#include <string>

namespace dermis::oiio {

/// The module, loaded on first use.
Result<const OiioApi*> oiioApi();

/// Loads the module from exactly `path` (not cached; for tests and diagnostics). Unavailable when
/// the file cannot be opened, has no `dermis_oiio_api` symbol or has another ABI version.
Result<const OiioApi*> loadOiioModule(const std::string& path);

} // namespace dermis::oiio
