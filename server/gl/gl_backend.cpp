// Names of the GL backends (see gl_backend.hpp).
#include "gl/gl_backend.hpp"

namespace dermis {

std::string_view toString(GlBackend b) {
    switch (b) {
    case GlBackend::Auto: return "auto";
    case GlBackend::EglDevice: return "egl-device";
    case GlBackend::EglSurfaceless: return "egl-surfaceless";
    case GlBackend::OsMesa: return "osmesa";
    }
    return "auto";
}

std::optional<GlBackend> glBackendFromString(std::string_view s) {
    for (GlBackend b : {GlBackend::Auto, GlBackend::EglDevice, GlBackend::EglSurfaceless,
                        GlBackend::OsMesa})
        if (toString(b) == s) return b;
    return std::nullopt;
}

} // namespace dermis
