// Dermis GL shell — the names of the places a GL context can come from, shared by the renderer
// (Renderer::create), the context code (gl_context) and the command line (--gl).
//
// Plain names only: no GL/EGL includes and no renderer; choosing and starting a backend is
// GlContext::create's job.
#pragma once

#include <optional>
#include <string_view>

namespace dermis {

/// Where the GL context comes from. Auto tries EglDevice (a hardware EGL device, NVIDIA first),
/// then EglSurfaceless (Mesa's surfaceless platform: llvmpipe without a GPU), then OsMesa.
enum class GlBackend { Auto, EglDevice, EglSurfaceless, OsMesa };

/// "auto", "egl-device", "egl-surfaceless", "osmesa" (the --gl and DERMIS_TEST_GL spellings).
std::string_view toString(GlBackend b);

/// The backend spelled `s` as toString writes it; nullopt for any other string (case-sensitive).
std::optional<GlBackend> glBackendFromString(std::string_view s);

} // namespace dermis
