// Test helper: the GL backend a GL suite asks for — $DERMIS_TEST_GL (osmesa, egl-surfaceless,
// egl-device; ctest sets it per registered backend), else Auto. An unknown name means Auto.
#pragma once

#include "gl/gl_backend.hpp"

#include <cstdlib>

namespace dermis::test {

inline GlBackend requestedBackend() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    if (!env || !*env) return GlBackend::Auto;
    auto b = glBackendFromString(env);
    return b ? *b : GlBackend::Auto;
}

} // namespace dermis::test
