// dermis-server — helpers every offline command shares: the error report on stderr, timing, the
// GL backend names, and creating an output file's folder. Not a library: used by server/app only.
#pragma once

#include "core/result.hpp"
#include "gl/gl_backend.hpp"

#include <chrono>
#include <string>
#include <vector>

namespace dermis::app {

/// Prints "dermis-server: error: <message>" to stderr; returns the exit code 1.
int fail(const Error& e);

/// Milliseconds since `t0`.
double msSince(std::chrono::steady_clock::time_point t0);

/// The backend named by --gl (CLI11 has checked it against kBackendNames).
GlBackend backendOf(const std::string& name);

extern const std::vector<std::string> kBackendNames;

/// Creates the folder `file` goes into (Ok when it exists). Io naming the folder on failure.
Status createFolderOf(const std::string& file);

} // namespace dermis::app
