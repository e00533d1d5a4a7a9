// libdermis_oiio.so — every use of OpenImageIO in Dermis, behind the plain function table of
// oiio_module.hpp. Built as a MODULE library and loaded with dlopen on first use
// (oiio_loader.cpp), so that the executables start without OpenImageIO's ≈ 260 libraries.
// Links OpenImageIO only: no Dermis library (errors are returned as OiioFailure values).
#include "io/oiio_module.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>

namespace dermis::oiio {
namespace {

using OIIO::ImageInput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

bool failWith(OiioFailure& f, ErrorCode code, std::string field, std::string what) {
    f.code = code;
    f.field = std::move(field);
    f.what = std::move(what);
    return false;
}

/// Adds OpenImageIO's pending global error text, if any, to `what`.
bool failParse(OiioFailure& f, const std::string& field, const std::string& what) {
    std::string detail = OIIO::geterror();
    return failWith(f, ErrorCode::Parse, field, detail.empty() ? what : what + " (" + detail + ")");
}

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

bool checkSpec(const std::string& name, const ImageSpec& spec, int maxSide, OiioFailure& f) {
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        return failWith(f, ErrorCode::Parse, name, "image has no pixels");
    if (spec.depth > 1)
        return failWith(f, ErrorCode::Unsupported, name, "volume images are not supported");
    if (spec.width > maxSide || spec.height > maxSide) // from the spec: no pixel decoded yet
        return failWith(f, ErrorCode::TooLarge, name,
                        "image is " + std::to_string(spec.width) + "x" +
                            std::to_string(spec.height) + ", larger than the limit of " +
                            std::to_string(maxSide) + " per side");
    return true;
}

/// Reads channel 0 of an open image with SPEC §2's value mapping.
bool readHeightFrom(ImageInput& in, const std::string& name, int maxSide, HeightImage& img,
                    OiioFailure& f) {
    const ImageSpec& spec = in.spec();
    if (!checkSpec(name, spec, maxSide, f)) return false;
    img = HeightImage(spec.width, spec.height);
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
    if (!ok) return failParse(f, name, "cannot decode pixels: " + in.geterror());
    return true;
}

/// Opens encoded bytes through an in-memory proxy (OpenImageIO's "oiio:ioproxy" open config) and
/// calls `fn` on the open image. Nothing is written anywhere (issue #12.8: a scratch file in the
/// system temp folder outlived a kill -9); a plugin that cannot read from memory is Unsupported.
/// OpenImageIO's GIF reader allocates and decodes the whole canvas (the logical screen) in
/// open(), before any spec can be checked: a GIF whose screen has a side over `maxSide` is
/// refused from its header (a 35-byte GIF declaring 16000² cost 1.3 GB and 2 s; found by
/// tests/fuzz/image_fuzz).
template <class Fn>
bool withOpenedMemory(const std::vector<std::uint8_t>& bytes, int maxSide, OiioFailure& f, Fn&& fn) {
    if (bytes.empty()) return failWith(f, ErrorCode::Parse, "", "empty image data");
    const std::string name = sniffName(bytes);
    if (name == "mem.gif" && bytes.size() >= 10) {
        const int w = bytes[6] | bytes[7] << 8, h = bytes[8] | bytes[9] << 8;
        if (w > maxSide || h > maxSide)
            return failWith(f, ErrorCode::InvalidArgument, "",
                            "GIF declares a " + std::to_string(w) + "x" + std::to_string(h) +
                                " screen, larger than the limit of " + std::to_string(maxSide) +
                                " per side");
    }
    OIIO::Filesystem::IOMemReader proxy(bytes.data(), bytes.size());
    OIIO::Filesystem::IOProxy* proxyPtr = &proxy;
    ImageSpec config;
    config.attribute("oiio:ioproxy", TypeDesc::PTR, &proxyPtr);
    // Values as stored: no premultiplication of colour by alpha (glTF textures and pattern
    // images are unassociated).
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = ImageInput::create(name, false, &config);
    if (!in) return failParse(f, "", "unrecognised image data");
    if (!in->supports("ioproxy")) {
        OIIO::geterror(); // clear
        return failWith(f, ErrorCode::Unsupported, "",
                        std::string("this image format (") + in->format_name() +
                            ") cannot be decoded from memory");
    }
    ImageSpec spec;
    if (!in->open(name, spec, config))
        return failParse(f, "", "unrecognised or corrupt image data: " + in->geterror());
    return fn(*in);
}

bool readHeight(const std::string* path, const std::vector<std::uint8_t>* bytes, int maxSide,
                HeightImage& out, OiioFailure& f) {
    try {
        if (path) {
            auto in = ImageInput::open(*path);
            if (!in) return failParse(f, *path, "cannot open image");
            return readHeightFrom(*in, *path, maxSide, out, f);
        }
        if (!bytes) return failWith(f, ErrorCode::InvalidArgument, "", "no path and no bytes");
        return withOpenedMemory(*bytes, maxSide, f, [&](ImageInput& in) {
            return readHeightFrom(in, "", maxSide, out, f);
        });
    } catch (const std::bad_alloc&) {
        return failWith(f, ErrorCode::TooLarge, "", "not enough memory to decode the image");
    } catch (const std::exception& e) {
        // Plugins throw on corrupt data (a GIF screen of 65535² threw std::length_error out of
        // ImageInput::create; found by image_fuzz): bad bytes, not a server fault.
        return failParse(f, "", std::string("corrupt image data (") + e.what() + ")");
    }
}

bool decodeRgba8(const std::vector<std::uint8_t>& bytes, int maxSide, Image8& out,
                 OiioFailure& f) {
    try {
        return withOpenedMemory(bytes, maxSide, f, [&](ImageInput& in) {
            const ImageSpec& spec = in.spec();
            if (!checkSpec("", spec, maxSide, f)) return false;
            const int nc = std::min(spec.nchannels, 4);
            std::vector<std::uint8_t> px(static_cast<std::size_t>(spec.width) * spec.height * nc);
            if (!in.read_image(0, 0, 0, nc, TypeDesc::UINT8, px.data()))
                return failParse(f, "", "cannot decode pixels: " + in.geterror());
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
            return true;
        });
    } catch (const std::bad_alloc&) {
        return failWith(f, ErrorCode::TooLarge, "", "not enough memory to decode the image");
    } catch (const std::exception& e) {
        return failParse(f, "", std::string("corrupt image data (") + e.what() + ")");
    }
}

bool encodeExr(int width, int height, int channels, const char* const* names,
               const float* pixels, bool half, std::vector<std::uint8_t>& out, OiioFailure& f) {
    try {
        std::vector<unsigned char> buf;
        OIIO::Filesystem::IOVecOutput proxy(buf);
        auto writer = OIIO::ImageOutput::create("map.exr", &proxy);
        if (!writer || !writer->supports("ioproxy")) {
            std::string detail = OIIO::geterror();
            return failWith(f, ErrorCode::Unsupported, "format",
                            "OpenImageIO cannot write EXR to memory" +
                                (detail.empty() ? "" : " (" + detail + ")"));
        }
        ImageSpec spec(width, height, channels, half ? TypeDesc::HALF : TypeDesc::FLOAT);
        spec.channelnames.assign(names, names + channels);
        spec.alpha_channel = -1;
        for (int c = 0; c < channels; ++c)
            if (spec.channelnames[static_cast<std::size_t>(c)] == "A") spec.alpha_channel = c;
        if (!writer->open("map.exr", spec) || !writer->write_image(TypeDesc::FLOAT, pixels) ||
            !writer->close())
            return failWith(f, ErrorCode::Io, "", "cannot encode EXR: " + writer->geterror());
        out.assign(buf.begin(), buf.end());
        return true;
    } catch (const std::exception& e) {
        return failWith(f, ErrorCode::Internal, "", std::string("OpenImageIO threw: ") + e.what());
    }
}

bool readRgbFloat(const std::string& path, int maxSide, int& width, int& height,
                  std::vector<float>& rgb, OiioFailure& f) {
    try {
        auto in = ImageInput::open(path);
        if (!in) return failParse(f, path, "cannot open image: " + OIIO::geterror());
        const ImageSpec& spec = in->spec();
        if (!checkSpec(path, spec, maxSide, f)) return false;
        const int nc = std::min(spec.nchannels, 3);
        std::vector<float> px(static_cast<std::size_t>(spec.width) * spec.height * nc);
        if (!in->read_image(0, 0, 0, nc, TypeDesc::FLOAT, px.data()))
            return failParse(f, path, "cannot decode pixels: " + in->geterror());
        width = spec.width;
        height = spec.height;
        rgb.resize(static_cast<std::size_t>(width) * height * 3);
        for (std::size_t k = 0, n = px.size() / nc; k < n; ++k)
            for (int c = 0; c < 3; ++c) rgb[k * 3 + c] = px[k * nc + (nc == 3 ? c : 0)];
        return true;
    } catch (const std::bad_alloc&) {
        return failWith(f, ErrorCode::TooLarge, path, "not enough memory to decode the image");
    } catch (const std::exception& e) {
        return failParse(f, path, std::string("corrupt image data (") + e.what() + ")");
    }
}

const OiioApi kApi = {kAbiVersion, &readHeight, &decodeRgba8, &encodeExr, &readRgbFloat};

} // namespace
} // namespace dermis::oiio

extern "C" __attribute__((visibility("default"))) const dermis::oiio::OiioApi* dermis_oiio_api() {
    return &dermis::oiio::kApi;
}
