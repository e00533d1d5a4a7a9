// dermis-patterngen — writes the built-in pattern library (SPEC §3):
//   dermis-patterngen --out DIR [--size N]
// DIR receives <id>.png (16-bit grey, SPEC §2 value mapping), manifest.json (dermis.patterns/1)
// and contact-sheet.png (8-bit RGB overview). Output is bit-identical from run to run.
// Exit status: 0 on success, 1 when a file cannot be written, 2 on bad usage.
#include "patterns.hpp"

#include "io/atomic_file.hpp"
#include "io/image_io.hpp"

#include <CLI/CLI.hpp>
#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <iostream>
#include <string>

namespace {

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
    CLI::App app{"Writes the built-in height patterns (16-bit PNG), manifest.json and "
                 "contact-sheet.png into a folder"};
    app.add_option("--out", outDir, "Output folder (created if needed)")->required();
    app.add_option("--size", size, "Side of each pattern in pixels")->check(CLI::Range(16, 4096));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }

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

    const std::string manifestText = dermis::toJson(manifest).dump(2) + "\n";
    if (auto st = dermis::writeFileAtomically(
            (dir / "manifest.json").string(),
            std::vector<std::uint8_t>(manifestText.begin(), manifestText.end()));
        !st) {
        std::cerr << st.error().message << "\n";
        return 1;
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
