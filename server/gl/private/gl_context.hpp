// Dermis GL shell (internal) — a headless GL 4.3 core context from one of three backends, with
// the GL entry points loaded by the glad2 loader generated at build time (it takes any
// get-proc-address function, so EGL and OSMesa share one binary; libepoxy aborts under OSMesa).
//
// The context is current on the creating thread only and must be destroyed on it. The OSMesa
// library is opened with dlopen only when that backend is tried. No EGL/GL types in this header.
#pragma once

#include "core/result.hpp"
#include "gl/gl_backend.hpp"

#include <memory>
#include <string>
#include <vector>

namespace dermis::gl {

class GlContext {
public:
    /// Creates the context and makes it current on this thread. `tried` receives one line per
    /// backend that failed ("egl-device: no hardware EGL device"). Fails (Unavailable) when none
    /// of the backends asked for starts.
    static Result<std::unique_ptr<GlContext>> create(GlBackend backend,
                                                     std::vector<std::string>& tried);
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    GlBackend backend() const { return backend_; }
    const std::string& device() const { return device_; }

    struct Impl;

private:
    GlContext() = default;
    GlBackend backend_ = GlBackend::Auto;
    std::string device_;
    std::unique_ptr<Impl> impl_;
};

} // namespace dermis::gl
