// Pattern images and float height maps through OpenImageIO. See image_io.hpp for the value
// mapping and failure modes.
#include "image_io.hpp"

#include "io/atomic_file.hpp" // writeFileAtomically

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

namespace dermis {
namespace {

using OIIO::ImageInput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

/// A file name whose extension selects the OpenImageIO plugin for encoded bytes (by magic).
std::string sniffName(const std::vector<std::uint8_t>& b) {
    auto starts = [&](std::initializer_list<std::uint8_t> m) {
        if (b.size() < m.size()) return false;
        return std::equal(m.begin(), m.end(), b.begin());
    };
    if (starts({0x89, 'P', 'N', 'G'})) return "mem.png";
    if (starts({0xFF, 0xD8, 0xFF})) return "mem.jpg";
    if (starts({'I', 'I', 42, 0}) || starts({'M', 'M', 0, 42})) return "mem.tif";
    if (starts({0x76, 0x2F, 0x31, 0x01})) return "mem.exr";
    if (starts({'8', 'B', 'P', 'S'})) return "mem.psd";
    if (starts({'B', 'M'})) return "mem.bmp";
    if (starts({'#', '?'})) return "mem.hdr";
    if (starts({'R', 'I', 'F', 'F'})) return "mem.webp";
    if (starts({'G', 'I', 'F'})) return "mem.gif";
    return "mem.tga"; // TGA has no magic number
}

/// Largest side decodeImage8 decodes (glTF textures; the loader's budget is checked before).
constexpr int kMaxDecodeSide = 16384;

Error oiioError(const char* where, const std::string& field, const std::string& what) {
    std::string detail = OIIO::geterror();
    return makeError(ErrorCode::Parse, where, field, detail.empty() ? what : what + " (" + detail + ")");
}

Status checkSpec(const char* where, const std::string& name, const ImageSpec& spec, int maxSide) {
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        return makeError(ErrorCode::Parse, where, name, "image has no pixels");
    if (spec.depth > 1)
        return makeError(ErrorCode::Unsupported, where, name, "volume images are not supported");
    if (spec.width > maxSide || spec.height > maxSide)
        return makeError(ErrorCode::InvalidArgument, where, name,
                         "image is " + std::to_string(spec.width) + "x" +
                             std::to_string(spec.height) + ", larger than the limit of " +
                             std::to_string(maxSide) + " per side");
    return Ok{};
}

/// Reads channel 0 of an open image with SPEC §2's value mapping.
Result<HeightImage> readHeight(ImageInput& in, const char* where, const std::string& name) {
    const ImageSpec& spec = in.spec();
    if (auto s = checkSpec(where, name, spec, kMaxPatternSize); !s) return s.error();
    HeightImage img(spec.width, spec.height);
    const std::size_t n = img.data.size();
    const auto base = TypeDesc::BASETYPE(spec.format.basetype);
    auto clamp1 = [](double v) { return static_cast<float>(std::clamp(v, -1.0, 1.0)); };
    bool ok = false;
    if (base == TypeDesc::UINT8) {
        std::vector<std::uint8_t> px(n);
        ok = in.read_image(0, 0, 0, 1, TypeDesc::UINT8, px.data());
        for (std::size_t k = 0; ok && k < n; ++k) img.data[k] = clamp1((px[k] - 128.0) / 127.0);
    } else if (base == TypeDesc::UINT16) {
        std::vector<std::uint16_t> px(n);
        ok = in.read_image(0, 0, 0, 1, TypeDesc::UINT16, px.data());
        for (std::size_t k = 0; ok && k < n; ++k)
            img.data[k] = clamp1((px[k] - 32768.0) / 32767.0);
    } else if (base == TypeDesc::HALF || base == TypeDesc::FLOAT || base == TypeDesc::DOUBLE) {
        ok = in.read_image(0, 0, 0, 1, TypeDesc::FLOAT, img.data.data());
        for (std::size_t k = 0; ok && k < n; ++k) {
            float v = img.data[k];
            img.data[k] = std::isfinite(v) ? clamp1(v) : 0.0f;
        }
    } else {
        // Other integer types: OpenImageIO normalises to [0, 1]; map 0.5 to height 0.
        ok = in.read_image(0, 0, 0, 1, TypeDesc::FLOAT, img.data.data());
        for (std::size_t k = 0; ok && k < n; ++k) img.data[k] = clamp1(2.0 * img.data[k] - 1.0);
    }
    if (!ok) return oiioError(where, name, "cannot decode pixels: " + in.geterror());
    return img;
}

/// Opens encoded bytes named `name` (sniffName) through an in-memory proxy and calls `fn` on the
/// open image; withOpenedMemory's body (may throw what the plugins throw).
template <class Fn>
auto openMemory(const std::vector<std::uint8_t>& bytes, const char* where, const std::string& name,
                Fn& fn) -> decltype(fn(std::declval<ImageInput&>())) {
    OIIO::Filesystem::IOMemReader proxy(bytes.data(), bytes.size());
    OIIO::Filesystem::IOProxy* proxyPtr = &proxy;
    ImageSpec config;
    config.attribute("oiio:ioproxy", TypeDesc::PTR, &proxyPtr);
    // Values as stored: no premultiplication of colour by alpha (glTF textures and pattern
    // images are unassociated).
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = ImageInput::create(name, false, &config);
    if (!in) return oiioError(where, "", "unrecognised image data");
    if (!in->supports("ioproxy")) {
        OIIO::geterror(); // clear
        return makeError(ErrorCode::Unsupported, where, "",
                         std::string("this image format (") + in->format_name() +
                             ") cannot be decoded from memory");
    }
    ImageSpec spec;
    if (!in->open(name, spec, config))
        return oiioError(where, "", "unrecognised or corrupt image data: " + in->geterror());
    return fn(*in);
}

/// Opens encoded bytes through an in-memory proxy (OpenImageIO's "oiio:ioproxy" open config) and
/// calls `fn` on the open image. Nothing is written anywhere (issue #12.8: a scratch file in the
/// system temp folder outlived a kill -9); a plugin that cannot read from memory is Unsupported.
/// OpenImageIO's GIF reader allocates and decodes the whole canvas (the logical screen) in
/// open(), before any spec can be checked: a GIF whose screen has a side over `maxSide` is
/// refused from its header (a 35-byte GIF declaring 16000² cost 1.3 GB and 2 s; found by
/// tests/fuzz/image_fuzz). Exceptions thrown by the plugins on corrupt data (a GIF screen of
/// 65535² threw std::length_error out of ImageInput::create) become Parse errors; running out of
/// memory, TooLarge.
template <class Fn>
auto withOpenedMemory(const std::vector<std::uint8_t>& bytes, const char* where, int maxSide,
                      Fn&& fn) -> decltype(fn(std::declval<ImageInput&>())) {
    if (bytes.empty()) return makeError(ErrorCode::Parse, where, "", "empty image data");
    const std::string name = sniffName(bytes);
    if (name == "mem.gif" && bytes.size() >= 10) {
        const int w = bytes[6] | bytes[7] << 8, h = bytes[8] | bytes[9] << 8;
        if (w > maxSide || h > maxSide)
            return makeError(ErrorCode::InvalidArgument, where, "",
                             "GIF declares a " + std::to_string(w) + "x" + std::to_string(h) +
                                 " screen, larger than the limit of " + std::to_string(maxSide) +
                                 " per side");
    }
    try {
        return openMemory(bytes, where, name, fn);
    } catch (const std::bad_alloc&) {
        return makeError(ErrorCode::TooLarge, where, "", "not enough memory to decode the image");
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Parse, where, "",
                         std::string("corrupt image data (") + e.what() + ")");
    }
}

} // namespace

Result<HeightImage> readHeightImage(const std::string& path) {
    const char* where = "dermis::readHeightImage";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        return makeError(ErrorCode::NotFound, where, path, "no such file");
    auto in = ImageInput::open(path);
    if (!in) return oiioError(where, path, "cannot open image");
    return readHeight(*in, where, path);
}

Result<HeightImage> readHeightImageFromMemory(const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::readHeightImageFromMemory";
    return withOpenedMemory(bytes, where, kMaxPatternSize,
                            [&](ImageInput& in) { return readHeight(in, where, ""); });
}

Result<Image8> decodeImage8(const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::decodeImage8";
    return withOpenedMemory(bytes, where, kMaxDecodeSide, [&](ImageInput& in) -> Result<Image8> {
        const ImageSpec& spec = in.spec();
        if (auto s = checkSpec(where, "", spec, kMaxDecodeSide); !s) return s.error();
        const int nc = std::min(spec.nchannels, 4);
        std::vector<std::uint8_t> px(static_cast<std::size_t>(spec.width) * spec.height * nc);
        if (!in.read_image(0, 0, 0, nc, TypeDesc::UINT8, px.data()))
            return oiioError(where, "", "cannot decode pixels: " + in.geterror());
        Image8 out;
        out.width = spec.width;
        out.height = spec.height;
        out.rgba.resize(static_cast<std::size_t>(spec.width) * spec.height * 4);
        for (std::size_t k = 0, n = px.size() / nc; k < n; ++k) {
            const std::uint8_t* s = &px[k * nc];
            std::uint8_t* d = &out.rgba[k * 4];
            if (nc >= 3) {
                d[0] = s[0], d[1] = s[1], d[2] = s[2];
                d[3] = nc == 4 ? s[3] : 255;
            } else {
                d[0] = d[1] = d[2] = s[0];
                d[3] = nc == 2 ? s[1] : 255;
            }
        }
        return out;
    });
}

namespace {

/// Encodes one channel through OpenImageIO into memory; `name` picks the writer by extension.
Result<std::vector<std::uint8_t>> encodeThroughOiio(const char* where, const char* name,
                                                    const ImageSpec& spec, TypeDesc type,
                                                    const void* pixels) {
    std::vector<unsigned char> buf;
    OIIO::Filesystem::IOVecOutput proxy(buf);
    auto out = OIIO::ImageOutput::create(name, &proxy);
    if (!out || !out->supports("ioproxy")) {
        std::string detail = OIIO::geterror();
        return makeError(ErrorCode::Unsupported, where, "format",
                         std::string("OpenImageIO cannot write ") + name + " to memory" +
                             (detail.empty() ? "" : " (" + detail + ")"));
    }
    if (!out->open(name, spec) || !out->write_image(type, pixels) || !out->close())
        return makeError(ErrorCode::Io, where, "", "cannot encode: " + out->geterror());
    return std::vector<std::uint8_t>(buf.begin(), buf.end());
}

Status checkHeightImage(const char* where, const HeightImage& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.data.size() != static_cast<std::size_t>(image.width) * image.height)
        return makeError(ErrorCode::InvalidArgument, where, "image", "empty or inconsistent image");
    return Ok{};
}

} // namespace

Result<std::vector<std::uint8_t>> encodeFloatExr(const HeightImage& image) {
    const char* where = "dermis::encodeFloatExr";
    if (auto s = checkHeightImage(where, image); !s) return s.error();
    ImageSpec spec(image.width, image.height, 1, TypeDesc::FLOAT);
    spec.channelnames = {"Y"};
    return encodeThroughOiio(where, "map.exr", spec, TypeDesc::FLOAT, image.data.data());
}

Result<std::vector<std::uint8_t>> encodeHeight16Png(const HeightImage& image) {
    const char* where = "dermis::encodeHeight16Png";
    if (auto s = checkHeightImage(where, image); !s) return s.error();
    std::vector<std::uint16_t> px(image.data.size());
    for (std::size_t k = 0; k < px.size(); ++k) {
        double v = std::clamp(static_cast<double>(image.data[k]), -1.0, 1.0);
        if (!std::isfinite(v)) v = 0.0;
        px[k] = static_cast<std::uint16_t>(std::lround(32768.0 + 32767.0 * v));
    }
    ImageSpec spec(image.width, image.height, 1, TypeDesc::UINT16);
    return encodeThroughOiio(where, "map.png", spec, TypeDesc::UINT16, px.data());
}

Result<std::vector<std::uint8_t>> encodeF32(const HeightImage& image) {
    if (auto s = checkHeightImage("dermis::encodeF32", image); !s) return s.error();
    std::vector<std::uint8_t> out(image.data.size() * sizeof(float));
    for (std::size_t k = 0; k < image.data.size(); ++k) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &image.data[k], sizeof bits);
        for (int b = 0; b < 4; ++b) // little-endian whatever the host's order
            out[k * 4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(bits >> (8 * b));
    }
    return out;
}

Status writeFloatImage(const std::string& path, const HeightImage& image) {
    auto bytes = encodeFloatExr(image);
    if (!bytes) return bytes.error();
    return writeFileAtomically(path, *bytes, Durability::Atomic, "dermis::writeFloatImage");
}

Status writeHeight16Png(const std::string& path, const HeightImage& image) {
    auto bytes = encodeHeight16Png(image);
    if (!bytes) return bytes.error();
    return writeFileAtomically(path, *bytes, Durability::Atomic, "dermis::writeHeight16Png");
}

} // namespace dermis
