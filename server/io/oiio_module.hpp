// Dermis io shell (internal) — the interface of libdermis_oiio.so, the module that holds every
// use of OpenImageIO. Linking OpenImageIO into an executable costs ≈ 0.23 s of process start on
// Debian 12 (≈ 260 shared libraries to map and relocate before main), so the executables do not
// link it: the common formats (PNG, JPEG) go through libpng / libjpeg-turbo directly
// (image_decode.hpp), and the rest (EXR in and out, TIFF, BMP, HDR, WebP, GIF, TGA, PSD, CMYK
// JPEG, …) through this module, loaded with dlopen on first use (oiio_loader.hpp).
//
// The module exports one C symbol, `dermis_oiio_api`, returning a table of plain functions. They
// take and return only standard-library and core value types (no OpenImageIO types), report
// failure as an OiioFailure (code, field, text) that the host turns into a Result with its own
// function name, never throw, and are thread-safe. Host and module are built together from this
// tree with the same compiler: `abiVersion` guards against a stale module beside a newer binary.
#pragma once

#include "core/heightmap.hpp"
#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dermis::oiio {

/// Bumped whenever OiioApi or the meaning of its functions changes.
constexpr int kAbiVersion = 2;

/// The file name the module is built as, looked up beside the executable.
constexpr const char* kModuleFileName = "libdermis_oiio.so";

/// What went wrong; the host prefixes its function name (makeError(code, where, field, what)).
struct OiioFailure {
    ErrorCode code = ErrorCode::Internal;
    std::string field;
    std::string what;
};

struct OiioApi {
    int abiVersion = 0;
    /// Channel 0 of an image with SPEC §2's value mapping (image_io.hpp). Exactly one of `path`
    /// (a file, opened by OpenImageIO, alpha associated as OpenImageIO does by default) or
    /// `bytes` (decoded in memory through an IOProxy, alpha unassociated) is non-null. Sides over
    /// `maxSide` → InvalidArgument; undecodable → Parse; a format without memory reading →
    /// Unsupported.
    bool (*readHeight)(const std::string* path, const std::vector<std::uint8_t>* bytes,
                       int maxSide, HeightImage& out, OiioFailure& failure);
    /// Encoded bytes to RGBA8 (grey → RGB, missing alpha → 255, alpha unassociated), converted
    /// to 8 bits by OpenImageIO. Same failures as readHeight.
    bool (*decodeRgba8)(const std::vector<std::uint8_t>& bytes, int maxSide, Image8& out,
                        OiioFailure& failure);
    /// Encodes `channels` interleaved float planes of width·height pixels (row 0 first) as an
    /// OpenEXR in memory with OpenImageIO's default compression, stored as half floats when
    /// `half`, else as 32-bit floats; `names` holds `channels` channel names. Io or Unsupported
    /// on failure.
    bool (*encodeExr)(int width, int height, int channels, const char* const* names,
                      const float* pixels, bool half, std::vector<std::uint8_t>& out,
                      OiioFailure& failure);
    /// The first three channels of the image file `path` as linear float RGB (grey → RGB),
    /// width·height·3 values, row 0 first, as stored (an HDR's or EXR's radiance; 8-bit formats
    /// as OpenImageIO converts them). Sides over `maxSide` → TooLarge from the spec; unreadable →
    /// Parse.
    bool (*readRgbFloat)(const std::string& path, int maxSide, int& width, int& height,
                         std::vector<float>& rgb, OiioFailure& failure);
};

} // namespace dermis::oiio

/// The module's one entry point (extern "C": looked up by name with dlsym).
extern "C" const dermis::oiio::OiioApi* dermis_oiio_api();
