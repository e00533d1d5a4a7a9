// Helpers shared by tests that touch files: a temporary folder, whole-file reads and writes,
// image writers that produce exact pixel values through OpenImageIO, the command-line runner and
// a tiny multi-file glTF.
#pragma once

#include "BuildPaths.hpp"
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace dermis::test {

/// A fresh folder under the system temp dir, removed on destruction.
class TempDir {
public:
    TempDir() {
        std::random_device rd;
        path_ = std::filesystem::temp_directory_path() /
                ("dermis-test-" + std::to_string(rd()) + std::to_string(rd()));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    std::string operator/(const std::string& name) const { return (path_ / name).string(); }
    std::string str() const { return path_.string(); }

private:
    std::filesystem::path path_;
};

inline std::vector<std::uint8_t> readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void writeBytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline void writeText(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

/// Writes `pixels` (w·h·channels values of type T) with OpenImageIO; format from the extension.
template <class T>
void writeImage(const std::string& path, int w, int h, int channels, const std::vector<T>& pixels,
                OIIO::TypeDesc type) {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out) << path;
    OIIO::ImageSpec spec(w, h, channels, type);
    ASSERT_TRUE(out->open(path, spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(type, pixels.data())) << out->geterror();
    ASSERT_TRUE(out->close());
}

/// What a run of the dermis-server command line printed and returned.
struct CliRun {
    int code = -1;
    std::string err, out;
};

/// Runs `dermis-server <args>` (dermis::build::serverExe()), capturing stdout and stderr in `dir`.
inline CliRun runServer(const TempDir& dir, const std::string& args) {
    const std::string cmd = std::string(dermis::build::serverExe()) + " " + args + " >" +
                            (dir / "out.txt") + " 2>" + (dir / "err.txt");
    const int status = std::system(cmd.c_str());
    CliRun r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    auto out = readBytes(dir / "out.txt"), err = readBytes(dir / "err.txt");
    r.out.assign(out.begin(), out.end());
    r.err.assign(err.begin(), err.end());
    return r;
}

/// A Radiance .hdr of w × h texels (flat RGBE scanlines, the format's header): linear radiance
/// `sky` (rgb) in the rows above the horizon (the upper half) and `ground` below it.
inline std::string radianceHdr(int w, int h, const float (&sky)[3], const float (&ground)[3]) {
    std::string text = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " +
                       std::to_string(w) + "\n";
    auto rgbe = [](const float (&rgb)[3]) {
        std::string t(4, '\0');
        const float v = std::max(rgb[0], std::max(rgb[1], rgb[2]));
        if (v <= 0.0f) return t;
        int e = 0;
        const float scale = std::frexp(v, &e) * 256.0f / v;
        t = {static_cast<char>(rgb[0] * scale), static_cast<char>(rgb[1] * scale),
             static_cast<char>(rgb[2] * scale), static_cast<char>(e + 128)};
        return t;
    };
    const std::string top = rgbe(sky), bottom = rgbe(ground);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            text += y < h / 2 ? top : bottom;
    return text;
}

/// A one-triangle glTF 2.0 document whose only buffer is the external file `binName`, and that
/// buffer's bytes (3 float positions, 3 uint16 indices).
inline std::pair<std::string, std::string> triangleGltf(const std::string& binName) {
    std::string bin(44, '\0');
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::uint16_t idx[3] = {0, 1, 2};
    std::memcpy(bin.data(), pos, sizeof pos);
    std::memcpy(bin.data() + 36, idx, sizeof idx);
    const nlohmann::json gltf = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}, {"name", "tri"}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
        {"buffers", {{{"uri", binName}, {"byteLength", 44}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                         {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 6}}}},
        {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                        {"min", {0, 0, 0}}, {"max", {1, 1, 0}}},
                       {{"bufferView", 1}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}}};
    return {gltf.dump(), bin};
}

} // namespace dermis::test
