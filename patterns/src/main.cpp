// dermis-patterngen — writes the built-in pattern library (SPEC §3):
//   dermis-patterngen --out DIR [--size N]
// DIR receives <id>.png (16-bit grey, SPEC §2 value mapping), manifest.json (dermis.patterns/1)
// and contact-sheet.png (8-bit RGB overview). Output is bit-identical from run to run.
#include "patterns.hpp"

#include "io/image_io.hpp"

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

namespace {

int usage(const char* argv0) {
    std::cerr << "usage: " << argv0 << " --out DIR [--size N]\n"
              << "  writes the built-in height patterns (16-bit PNG), manifest.json and\n"
              << "  contact-sheet.png into DIR; N (default 512) is the side in pixels, 16..4096\n";
    return 2;
}

bool writeRgbPng(const std::string& path, const dermis::patterngen::RgbImage& img) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return false;
    OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::UINT8);
    if (!out->open(path, spec)) {
        std::cerr << out->geterror() << "\n";
        return false;
    }
    bool ok = out->write_image(OIIO::TypeDesc::UINT8, img.data.data());
    return out->close() && ok;
}

} // namespace

int main(int argc, char** argv) {
    std::string outDir;
    int size = 512;
    for (int k = 1; k < argc; ++k) {
        std::string a = argv[k];
        if ((a == "--out" || a == "--size") && k + 1 < argc) {
            std::string v = argv[++k];
            if (a == "--out") {
                outDir = v;
            } else {
                char* end = nullptr;
                long n = std::strtol(v.c_str(), &end, 10);
                if (end == v.c_str() || *end != '\0' || n < 16 || n > 4096) {
                    std::cerr << "--size: expected an integer in [16, 4096], got '" << v << "'\n";
                    return 2;
                }
                size = static_cast<int>(n);
            }
        } else if (a == "-h" || a == "--help") {
            usage(argv[0]);
            return 0;
        } else {
            return usage(argv[0]);
        }
    }
    if (outDir.empty()) return usage(argv[0]);

    std::error_code ec;
    std::filesystem::create_directories(outDir, ec);
    if (ec) {
        std::cerr << "cannot create " << outDir << ": " << ec.message() << "\n";
        return 1;
    }
    const std::filesystem::path dir(outDir);

    auto library = dermis::patterngen::generateLibrary(size);
    dermis::PatternManifest manifest;
    for (const auto& p : library) {
        auto st = dermis::writeHeight16Png((dir / p.info.file).string(), p.image);
        if (!st) {
            std::cerr << st.error().message << "\n";
            return 1;
        }
        manifest.patterns.push_back(p.info);
    }

    {
        std::ofstream out(dir / "manifest.json", std::ios::binary | std::ios::trunc);
        out << dermis::toJson(manifest).dump(2) << "\n";
        if (!out) {
            std::cerr << "cannot write " << (dir / "manifest.json").string() << "\n";
            return 1;
        }
    }

    if (!writeRgbPng((dir / "contact-sheet.png").string(),
                     dermis::patterngen::contactSheet(library))) {
        std::cerr << "cannot write " << (dir / "contact-sheet.png").string() << "\n";
        return 1;
    }
    std::cout << "wrote " << library.size() << " patterns (" << size << "x" << size
              << "), manifest.json and contact-sheet.png to " << outDir << "\n";
    return 0;
}
