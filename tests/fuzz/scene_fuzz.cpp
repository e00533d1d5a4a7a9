// libFuzzer target: scene documents (core/scene.hpp) — parseSceneText on any text with the
// built-in pattern manifest (patterns/manifest.json, read once), and for every document that
// parses, the round trip SPEC promises: toJson(scene) parses again, and serialising that gives
// the same JSON.
//
// What counts as a bug: a crash, a sanitizer report, a hang, or a broken round trip. An Error
// return is the expected answer to bad documents. Built only with -DDERMIS_FUZZ=ON; run with
// `make fuzz`. DERMIS_SOURCE_DIR locates the manifest.
#include "core/scene.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace {

dermis::PatternManifest loadManifest() {
    std::ifstream in(std::string(DERMIS_SOURCE_DIR) + "/patterns/manifest.json");
    std::stringstream text;
    text << in.rdbuf();
    auto doc = nlohmann::json::parse(text.str(), nullptr, false);
    auto manifest = dermis::parsePatternManifest(doc);
    if (!manifest) {
        std::fprintf(stderr, "scene_fuzz: cannot read patterns/manifest.json: %s\n",
                     manifest.error().message.c_str());
        std::abort();
    }
    return std::move(manifest).value();
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const dermis::PatternManifest manifest = loadManifest();
    const std::string text(reinterpret_cast<const char*>(data), size);
    auto scene = dermis::parseSceneText(text, manifest);
    if (!scene) return 0;
    const nlohmann::json once = dermis::toJson(*scene);
    auto again = dermis::parseScene(once, manifest);
    if (!again) {
        std::fprintf(stderr, "round trip refused: %s\n%s\n", again.error().message.c_str(),
                     once.dump().c_str());
        __builtin_trap();
    }
    if (dermis::toJson(*again) != once) {
        std::fprintf(stderr, "round trip changed the scene:\n%s\n%s\n", once.dump().c_str(),
                     dermis::toJson(*again).dump().c_str());
        __builtin_trap();
    }
    return 0;
}
