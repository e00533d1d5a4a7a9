// dermis (client) — images for `check`: PNG (libpng's simplified API) and JPEG (libjpeg-turbo)
// decoded to 8-bit RGBA, PNG encoding, and the comparison of two images as f3d's regression tests
// do it: a pixel differs when one channel differs by more than `threshold` (0…1 of full scale),
// and the images match when at most `fraction` of the pixels differ.
// No OpenImageIO, no GL. Decoding failures return false with a message; nothing throws.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dermis::cli {

struct Rgba8 {
    int width = 0, height = 0;
    std::vector<std::uint8_t> pixels; ///< width·height·4, row 0 at the top
};

/// PNG or JPEG bytes (sniffed) → RGBA8. False with `error` set when undecodable.
bool decodeImage(const std::string& bytes, Rgba8& out, std::string& error);
/// RGBA8 → PNG bytes. False with `error` set when libpng fails.
bool encodePng(const Rgba8& image, std::string& out, std::string& error);

struct Comparison {
    bool sizeMatches = false;
    std::size_t differing = 0;  ///< pixels over the threshold
    double fraction = 0.0;      ///< differing / pixels
    double maxDifference = 0.0; ///< the largest channel difference, 0…1
    bool pass = false;
    Rgba8 diff; ///< black where equal, red → yellow → white as the difference grows (same size)
};

/// Compares `actual` with `reference`. Images of different sizes never pass (no diff image).
Comparison compareImages(const Rgba8& actual, const Rgba8& reference, double threshold, double fraction);

} // namespace dermis::cli
