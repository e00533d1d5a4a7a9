// libFuzzer target: the glTF loader from memory (loadGltfFromFiles, gltf_loader.hpp), both
// steps — parse with the declared-size preflight (gltf_preflight.cpp) and image decoding — on
// any bytes, as an upload brings them. Input starting with "glTF" is a .glb, anything else a
// .gltf (JSON); the .gltf may name one external file, "b.bin" (1 KiB of counting bytes), to
// exercise external buffers and images; every other URI must fail cleanly.
//
// Small limits (below): a fuzzed file may legitimately declare a model or texture near the
// limits, and with the server's defaults (10⁶ triangles, 256 MB of texture) that is slow and
// can pass libFuzzer's -rss_limit_mb without any bug. What counts as a bug: a crash, a sanitizer
// report (memory, UB, leak), or a hang; an Error return is the expected answer to bad bytes.
// Built only with -DDERMIS_FUZZ=ON (tests/fuzz/CMakeLists.txt); run with `make fuzz`. With
// DERMIS_FUZZ_VERBOSE set, each input's outcome is printed (to check what a seed reaches).
#include "io/gltf_loader.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::vector<std::uint8_t> companion = [] {
        std::vector<std::uint8_t> b(1024);
        for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(i);
        return b;
    }();
    dermis::GltfLimits limits;
    limits.maxTriangles = 200000; // maxElements 600000, maxValues 14.4 M
    limits.maxJoints = 256;
    limits.maxParts = 512;
    limits.maxImageSide = 512;
    limits.maxTextureBytes = std::size_t(32) << 20;

    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const std::string mainFile = binary ? "m.glb" : "m.gltf";
    dermis::GltfFiles files;
    files[mainFile] = std::vector<std::uint8_t>(data, data + size);
    files["b.bin"] = companion;
    auto model = dermis::loadGltfFromFiles(files, mainFile, limits);
    static const bool verbose = std::getenv("DERMIS_FUZZ_VERBOSE") != nullptr;
    if (verbose)
        std::fprintf(stderr, "gltf_fuzz: %s\n",
                     model ? ("loaded, " + std::to_string(model->parts.size()) + " parts, " +
                              std::to_string(model->images.size()) + " images")
                                 .c_str()
                           : model.error().message.c_str());
    if (model) {
        // A loaded model honours the limits it was loaded with.
        for (const auto& img : model->images)
            if (img.width > limits.maxImageSide || img.height > limits.maxImageSide ||
                img.rgba.size() != std::size_t(img.width) * img.height * 4)
                __builtin_trap();
    }
    return 0;
}
