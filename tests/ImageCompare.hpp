// The one image-comparison helper of the tests: compares a rendered RGBA8 frame with a reference
// PNG (compareWithReference) or with another rendered frame (compareImages) under a tolerance,
// and on failure (or a missing reference) saves the actual image and a difference image beside
// the build's test output, naming them in the failure message.
//
// Set DERMIS_UPDATE_REFERENCES=1 to (re)write the reference from the actual image instead; the
// comparison then passes only if the write succeeds. References live in tests/reference/.
#pragma once

#include "core/model.hpp"
#include "io/frame_io.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

namespace dermis::test {

struct ImageTolerance {
    int channelThreshold = 40;      ///< a pixel differs when a colour channel differs by more
    double maxDifferingFraction = 0.015; ///< of all pixels
    double maxMeanAbsDiff = 3.0;    ///< mean over all colour channels, in 8-bit steps
};

/// Where failing comparisons leave their images: $DERMIS_TEST_OUTPUT or ./test-output.
inline std::filesystem::path testOutputDir() {
    const char* env = std::getenv("DERMIS_TEST_OUTPUT");
    std::filesystem::path dir = env && *env ? env : "test-output";
    std::filesystem::create_directories(dir);
    return dir;
}

inline ::testing::AssertionResult compareImages(const Image8& actual, const Image8& expected,
                                                const std::string& name, const ImageTolerance& tol);

inline ::testing::AssertionResult compareWithReference(const Image8& actual,
                                                       const std::string& referencePath,
                                                       const ImageTolerance& tol = {}) {
    const std::string name = std::filesystem::path(referencePath).stem().string();
    const char* update = std::getenv("DERMIS_UPDATE_REFERENCES");
    if (update && std::string(update) == "1") {
        std::filesystem::create_directories(std::filesystem::path(referencePath).parent_path());
        if (auto s = writeFrame(referencePath, actual); !s)
            return ::testing::AssertionFailure() << "cannot write " << referencePath << ": "
                                                 << s.error().message;
        return ::testing::AssertionSuccess() << "updated " << referencePath;
    }
    const std::string actualPath = (testOutputDir() / (name + ".actual.png")).string();
    auto saveActual = [&] { (void)writeFrame(actualPath, actual); };

    auto ref = decodeFrame(readBytes(referencePath));
    if (!ref) {
        saveActual();
        return ::testing::AssertionFailure()
               << "no readable reference " << referencePath << " (" << ref.error().message
               << "); actual image saved as " << actualPath
               << " — run with DERMIS_UPDATE_REFERENCES=1 to create it";
    }
    return compareImages(actual, *ref, name, tol);
}

/// `actual` against `expected` (both rendered) under `tol`; on failure both and their difference
/// are saved as <name>.actual.png, <name>.expected.png and <name>.diff.png in testOutputDir().
inline ::testing::AssertionResult compareImages(const Image8& actual, const Image8& expected,
                                                const std::string& name, const ImageTolerance& tol = {}) {
    const std::string actualPath = (testOutputDir() / (name + ".actual.png")).string();
    auto saveActual = [&] { (void)writeFrame(actualPath, actual); };
    const Image8* ref = &expected;
    if (ref->width != actual.width || ref->height != actual.height) {
        saveActual();
        return ::testing::AssertionFailure()
               << "size " << actual.width << "x" << actual.height << " differs from the reference "
               << ref->width << "x" << ref->height << "; actual saved as " << actualPath;
    }
    Image8 diff;
    diff.width = actual.width;
    diff.height = actual.height;
    diff.rgba.assign(actual.rgba.size(), 255);
    std::size_t differing = 0;
    double sum = 0.0;
    const std::size_t pixels = static_cast<std::size_t>(actual.width) * actual.height;
    for (std::size_t p = 0; p < pixels; ++p) {
        int worst = 0;
        for (int c = 0; c < 3; ++c) {
            const int d = std::abs(int(actual.rgba[p * 4 + c]) - int(ref->rgba[p * 4 + c]));
            worst = std::max(worst, d);
            sum += d;
        }
        if (worst > tol.channelThreshold) ++differing;
        const auto v = static_cast<std::uint8_t>(std::min(255, worst * 4));
        diff.rgba[p * 4] = diff.rgba[p * 4 + 1] = diff.rgba[p * 4 + 2] = v;
    }
    const double fraction = static_cast<double>(differing) / static_cast<double>(pixels);
    const double mean = sum / (3.0 * static_cast<double>(pixels));
    if (fraction <= tol.maxDifferingFraction && mean <= tol.maxMeanAbsDiff)
        return ::testing::AssertionSuccess();
    saveActual();
    (void)writeFrame((testOutputDir() / (name + ".expected.png")).string(), expected);
    const std::string diffPath = (testOutputDir() / (name + ".diff.png")).string();
    (void)writeFrame(diffPath, diff);
    std::ostringstream msg;
    msg << name << ": " << fraction * 100.0 << "% of pixels differ by more than "
        << tol.channelThreshold << " (allowed " << tol.maxDifferingFraction * 100.0
        << "%), mean difference " << mean << " (allowed " << tol.maxMeanAbsDiff
        << "); actual saved as " << actualPath << ", difference as " << diffPath;
    return ::testing::AssertionFailure() << msg.str();
}

/// Fraction of pixels of `img` whose colour differs from its top-left (background) pixel by more
/// than 8 in a channel.
inline double coverage(const Image8& img) {
    std::size_t n = 0;
    const std::size_t pixels = static_cast<std::size_t>(img.width) * img.height;
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c)
            if (std::abs(int(img.rgba[p * 4 + c]) - int(img.rgba[c])) > 8) {
                ++n;
                break;
            }
    return pixels ? static_cast<double>(n) / static_cast<double>(pixels) : 0.0;
}

/// Mean absolute difference over all channels of two images of one size (1e9 when their sizes
/// differ or they are empty).
inline double meanAbsDiff(const Image8& a, const Image8& b) {
    if (a.rgba.size() != b.rgba.size() || a.rgba.empty()) return 1e9;
    double s = 0.0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i) s += std::abs(int(a.rgba[i]) - int(b.rgba[i]));
    return s / static_cast<double>(a.rgba.size());
}

} // namespace dermis::test
