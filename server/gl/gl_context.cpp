// Headless GL contexts: EGL device platform, Mesa's surfaceless EGL, OSMesa (dlopen).
#include "gl_context.hpp"

#include <glad/gl.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

namespace dermis::gl {

namespace {

constexpr int kGlMajor = 4, kGlMinor = 3;

// The few OSMesa declarations we need (GL/osmesa.h would drag in GL/gl.h next to glad's).
using OSMesaContext = struct osmesa_context*;
using OSMesaCreateContextAttribsFn = OSMesaContext (*)(const int*, OSMesaContext);
using OSMesaMakeCurrentFn = unsigned char (*)(OSMesaContext, void*, unsigned, int, int);
using OSMesaDestroyContextFn = void (*)(OSMesaContext);
using OSMesaGetProcAddressFn = void (*(*)(const char*))();
constexpr int OSMESA_FORMAT = 0x22, OSMESA_DEPTH_BITS = 0x30, OSMESA_STENCIL_BITS = 0x31,
              OSMESA_PROFILE = 0x33, OSMESA_CORE_PROFILE = 0x34,
              OSMESA_CONTEXT_MAJOR_VERSION = 0x36, OSMESA_CONTEXT_MINOR_VERSION = 0x37;
constexpr int OSMESA_RGBA = 0x1908;     // GL_RGBA
constexpr unsigned kGlUnsignedByte = 0x1401;

OSMesaGetProcAddressFn g_osmesaGetProcAddress = nullptr;

GLADapiproc eglLoad(const char* name) {
    return reinterpret_cast<GLADapiproc>(eglGetProcAddress(name));
}
GLADapiproc osmesaLoad(const char* name) {
    return reinterpret_cast<GLADapiproc>(g_osmesaGetProcAddress(name));
}

std::string eglErrorText() {
    char buf[32];
    std::snprintf(buf, sizeof buf, "EGL error 0x%04X", static_cast<unsigned>(eglGetError()));
    return buf;
}

bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

} // namespace

struct GlContext::Impl {
    // EGL
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    EGLSurface surface = EGL_NO_SURFACE;
    // OSMesa
    void* osmesaLib = nullptr;
    OSMesaContext osmesa = nullptr;
    OSMesaDestroyContextFn osmesaDestroy = nullptr;
    std::vector<unsigned char> osmesaBuffer;

    ~Impl() {
        if (context != EGL_NO_CONTEXT) {
            eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display, context);
        }
        if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
        if (display != EGL_NO_DISPLAY) eglTerminate(display);
        if (osmesa && osmesaDestroy) osmesaDestroy(osmesa);
        // The OSMesa library stays loaded: its atexit handlers and TLS may still refer to it.
    }

    /// Initialises `display` and creates a current 4.3 core context (surfaceless where
    /// supported, else a 1×1 pbuffer). Returns "" or why it failed.
    std::string startEgl() {
        EGLint major = 0, minor = 0;
        if (!eglInitialize(display, &major, &minor)) return "eglInitialize failed (" + eglErrorText() + ")";
        if (!eglBindAPI(EGL_OPENGL_API)) return "eglBindAPI(OpenGL) failed (" + eglErrorText() + ")";
        const char* exts = eglQueryString(display, EGL_EXTENSIONS);
        const bool surfaceless = hasExtension(exts, "EGL_KHR_surfaceless_context");
        const EGLint configAttribs[] = {EGL_SURFACE_TYPE, surfaceless ? 0 : EGL_PBUFFER_BIT,
                                        EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                        EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                                        EGL_NONE};
        EGLConfig config = nullptr;
        EGLint count = 0;
        if (!eglChooseConfig(display, configAttribs, &config, 1, &count) || count < 1)
            return "no EGL config with desktop OpenGL (" + eglErrorText() + ")";
        const EGLint ctxAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, kGlMajor,
                                     EGL_CONTEXT_MINOR_VERSION, kGlMinor,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                     EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        context = eglCreateContext(display, config, EGL_NO_CONTEXT, ctxAttribs);
        if (context == EGL_NO_CONTEXT)
            return "cannot create an OpenGL 4.3 core context (" + eglErrorText() + ")";
        if (!surfaceless) {
            const EGLint pbAttribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
            surface = eglCreatePbufferSurface(display, config, pbAttribs);
            if (surface == EGL_NO_SURFACE) return "cannot create a pbuffer (" + eglErrorText() + ")";
        }
        if (!eglMakeCurrent(display, surface, surface, context))
            return "eglMakeCurrent failed (" + eglErrorText() + ")";
        return "";
    }

    void resetEgl() {
        if (context != EGL_NO_CONTEXT) {
            eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display, context);
        }
        if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
        if (display != EGL_NO_DISPLAY) eglTerminate(display);
        display = EGL_NO_DISPLAY;
        context = EGL_NO_CONTEXT;
        surface = EGL_NO_SURFACE;
    }
};

namespace {

/// Loads the GL entry points for the current context; "" or why not.
std::string loadGl(GLADloadfunc load) {
    const int version = gladLoadGL(load);
    if (version == 0) return "the GL loader found no GL entry points";
    const int major = GLAD_VERSION_MAJOR(version), minor = GLAD_VERSION_MINOR(version);
    if (major < kGlMajor || (major == kGlMajor && minor < kGlMinor))
        return "OpenGL " + std::to_string(major) + "." + std::to_string(minor) +
               " is below the 4.3 core profile the renderer needs";
    return "";
}

std::string tryEglDevice(GlContext::Impl& impl, bool anyDevice, std::string& device) {
    const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!hasExtension(clientExts, "EGL_EXT_device_enumeration") &&
        !hasExtension(clientExts, "EGL_EXT_device_base"))
        return "the EGL library has no device enumeration (EGL_EXT_device_enumeration)";
    auto queryDevices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto queryDeviceString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
        eglGetProcAddress("eglQueryDeviceStringEXT"));
    auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!queryDevices || !queryDeviceString || !getPlatformDisplay)
        return "eglQueryDevicesEXT/eglGetPlatformDisplayEXT missing";
    EGLDeviceEXT devices[16];
    EGLint n = 0;
    if (!queryDevices(16, devices, &n) || n <= 0) return "no EGL devices";
    // Order: NVIDIA devices, other hardware (DRM) devices, then — only when asked for this
    // backend explicitly — software devices.
    struct Candidate {
        EGLDeviceEXT dev;
        int rank;
        std::string name;
    };
    std::vector<Candidate> candidates;
    for (EGLint i = 0; i < n; ++i) {
        const char* exts = queryDeviceString(devices[i], EGL_EXTENSIONS);
        const bool nvidia = hasExtension(exts, "EGL_NV_device_cuda");
        const bool software = hasExtension(exts, "EGL_MESA_device_software");
        const char* drm = hasExtension(exts, "EGL_EXT_device_drm")
                              ? queryDeviceString(devices[i], EGL_DRM_DEVICE_FILE_EXT)
                              : nullptr;
        std::string name = nvidia ? "NVIDIA EGL device" : software ? "software EGL device" : "EGL device";
        if (drm) name += std::string(" ") + drm;
        const int rank = nvidia ? 0 : software ? 2 : 1;
        if (rank == 2 && !anyDevice) continue;
        candidates.push_back({devices[i], rank, name});
    }
    if (candidates.empty()) return "no hardware EGL device (only software ones)";
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) { return a.rank < b.rank; });
    std::string why;
    for (const Candidate& c : candidates) {
        impl.display = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, c.dev, nullptr);
        if (impl.display == EGL_NO_DISPLAY) {
            why += c.name + ": no display; ";
            continue;
        }
        std::string err = impl.startEgl();
        if (err.empty()) err = loadGl(eglLoad);
        if (err.empty()) {
            device = c.name;
            return "";
        }
        why += c.name + ": " + err + "; ";
        impl.resetEgl();
    }
    return why.substr(0, why.size() - 2);
}

std::string tryEglSurfaceless(GlContext::Impl& impl, std::string& device) {
    const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!hasExtension(clientExts, "EGL_MESA_platform_surfaceless"))
        return "the EGL library has no surfaceless platform (EGL_MESA_platform_surfaceless)";
    auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!getPlatformDisplay) return "eglGetPlatformDisplayEXT missing";
    impl.display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (impl.display == EGL_NO_DISPLAY) return "no surfaceless display (" + eglErrorText() + ")";
    std::string err = impl.startEgl();
    if (err.empty()) err = loadGl(eglLoad);
    if (!err.empty()) {
        impl.resetEgl();
        return err;
    }
    const char* vendor = eglQueryString(impl.display, EGL_VENDOR);
    device = std::string("Mesa surfaceless platform") + (vendor ? std::string(" (") + vendor + ")" : "");
    return "";
}

std::string tryOsMesa(GlContext::Impl& impl, std::string& device) {
    for (const char* name : {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}) {
        impl.osmesaLib = dlopen(name, RTLD_NOW | RTLD_LOCAL);
        if (impl.osmesaLib) {
            device = name;
            break;
        }
    }
    if (!impl.osmesaLib) return "libOSMesa.so is not installed (Debian: libosmesa6)";
    auto create = reinterpret_cast<OSMesaCreateContextAttribsFn>(
        dlsym(impl.osmesaLib, "OSMesaCreateContextAttribs"));
    auto makeCurrent =
        reinterpret_cast<OSMesaMakeCurrentFn>(dlsym(impl.osmesaLib, "OSMesaMakeCurrent"));
    impl.osmesaDestroy =
        reinterpret_cast<OSMesaDestroyContextFn>(dlsym(impl.osmesaLib, "OSMesaDestroyContext"));
    g_osmesaGetProcAddress =
        reinterpret_cast<OSMesaGetProcAddressFn>(dlsym(impl.osmesaLib, "OSMesaGetProcAddress"));
    if (!create || !makeCurrent || !impl.osmesaDestroy || !g_osmesaGetProcAddress)
        return "libOSMesa lacks OSMesaCreateContextAttribs";
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24,
                           OSMESA_STENCIL_BITS, 8, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, kGlMajor,
                           OSMESA_CONTEXT_MINOR_VERSION, kGlMinor, 0};
    impl.osmesa = create(attribs, nullptr);
    if (!impl.osmesa) return "OSMesaCreateContextAttribs failed for a 4.3 core context";
    // OSMesa needs a colour buffer to be current; rendering goes to framebuffer objects.
    impl.osmesaBuffer.assign(4 * 4 * 4, 0);
    if (!makeCurrent(impl.osmesa, impl.osmesaBuffer.data(), kGlUnsignedByte, 4, 4))
        return "OSMesaMakeCurrent failed";
    return loadGl(osmesaLoad);
}

} // namespace

Result<std::unique_ptr<GlContext>> GlContext::create(GlBackend backend,
                                                     std::vector<std::string>& tried) {
    std::vector<GlBackend> order;
    if (backend == GlBackend::Auto)
        order = {GlBackend::EglDevice, GlBackend::EglSurfaceless, GlBackend::OsMesa};
    else
        order = {backend};
    for (GlBackend b : order) {
        std::unique_ptr<GlContext> ctx(new GlContext());
        ctx->impl_ = std::make_unique<Impl>();
        std::string why;
        switch (b) {
        case GlBackend::EglDevice:
            why = tryEglDevice(*ctx->impl_, backend == GlBackend::EglDevice, ctx->device_);
            break;
        case GlBackend::EglSurfaceless: why = tryEglSurfaceless(*ctx->impl_, ctx->device_); break;
        case GlBackend::OsMesa: why = tryOsMesa(*ctx->impl_, ctx->device_); break;
        case GlBackend::Auto: break;
        }
        if (why.empty()) {
            ctx->backend_ = b;
            return ctx;
        }
        tried.push_back(std::string(toString(b)) + ": " + why);
    }
    std::string all;
    for (const std::string& t : tried) all += (all.empty() ? "" : "; ") + t;
    return makeError(ErrorCode::Unavailable, "dermis::Renderer::create", "",
                     "no GL backend could start (tried " + all + ")");
}

GlContext::~GlContext() = default;

} // namespace dermis::gl
