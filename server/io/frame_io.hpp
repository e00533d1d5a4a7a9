// Dermis io shell — rendered frames out: fast PNG (ISA-L's igzip) and JPEG (libjpeg-turbo) encoders to
// memory for the server's responses, linear-light EXR through OpenImageIO in the module
// libdermis_oiio.so (loaded on first EXR, oiio_loader.hpp), and writing any of them to a file by
// extension.
//
// Frames are dermis::Image8: 8-bit RGBA, row 0 = top of the picture, colours sRGB-encoded, alpha
// straight (not premultiplied) and stored as is in every format (EXR included: RGB are not
// multiplied by alpha). Every function is thread-safe.
//
// Failure: an empty frame (width or height ≤ 0), a side over kMaxFrameSide or an rgba buffer
// whose size is not width·height·4 → ErrorCode::InvalidArgument naming the function and the
// field ("image", "image.rgba"); a bad argument → InvalidArgument naming it ("quality", the path
// for an unknown extension); a file that cannot be created, written or renamed into place →
// ErrorCode::Io with the path as `field`; an encoder's internal failure → ErrorCode::Io (for
// EXR, ErrorCode::Unsupported when OpenImageIO has no EXR writer, ErrorCode::Unavailable when
// the module cannot be loaded); undecodable bytes in
// decodeFrame → ErrorCode::Parse.
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dermis {

/// Largest frame side accepted by the encoders and decodeFrame, in pixels.
constexpr int kMaxFrameSide = 16384;

enum class FrameFormat { Png, Jpeg, Exr, Webp };

/// The format named by a path's extension: ".png" → Png, ".jpg"/".jpeg" → Jpeg, ".exr" → Exr,
/// ".webp" → Webp (lossless), case-insensitive; std::nullopt for anything else (including no extension).
std::optional<FrameFormat> frameFormatFromPath(const std::string& path);

/// Encodes a frame as PNG in memory: 8-bit RGBA (keepAlpha) or RGB (alpha dropped), not
/// interlaced, no colour chunks; the fixed SUB filter on every row, one zlib stream by ISA-L's
/// igzip at level 1 on the calling thread (≈ 1 ms for a 1024² frame's rows; zlib's fastest
/// setting took 7–12 ms for a 5 % smaller stream). Decodes to exactly the input bytes (alpha
/// included when kept).
Result<std::vector<std::uint8_t>> encodePng(const Image8& img, bool keepAlpha = true);

/// Encodes a frame as baseline JPEG in memory with libjpeg-turbo: 4:2:0 chroma subsampling,
/// accurate integer DCT, `quality` ∈ [1, 100] (InvalidArgument "quality" otherwise); alpha is
/// dropped (not composited: RGB are encoded as stored).
Result<std::vector<std::uint8_t>> encodeJpeg(const Image8& img, int quality = 90);

/// Encodes a frame in format `f`: Png = encodePng(img, keepAlpha) with alpha kept only when some
/// pixel's alpha is not 255 (an opaque frame, as every rendered one is, is written as RGB: ≈ 20 %
/// smaller, decoded to the same RGBA bytes), Jpeg = encodeJpeg(img, 90), Webp =
/// encodeWebpLossless(img, true) (io/webp_encode.hpp), Exr =
/// 4-channel (R, G, B, A) half-float OpenEXR in LINEAR light, encoded by OpenImageIO in memory
/// with its default compression: each colour byte c is decoded with the exact sRGB EOTF
/// (c/255 ≤ 0.04045 ? (c/255)/12.92 : ((c/255 + 0.055)/1.055)^2.4), alpha is a/255.
Result<std::vector<std::uint8_t>> encodeFrame(const Image8& img, FrameFormat f);

/// Writes a frame to `path` in the format of its extension (frameFormatFromPath; anything else →
/// InvalidArgument with the path as field), encoded as by encodeFrame, replaced whole through
/// writeFileAtomically (atomic_file.hpp, Durability::Atomic): readers never see a partial frame,
/// a symbolic link at `path` is replaced, not followed, and on failure `path` is left as it was.
/// Does not create folders and does not fsync.
Status writeFrame(const std::string& path, const Image8& img);

/// Decodes PNG or JPEG bytes (by magic number) to RGBA8 with libpng / libjpeg-turbo: values as
/// stored for 8-bit PNGs without colour chunks (such as encodePng's) and for JPEGs: no alpha
/// premultiplication (unlike decodeImage8, whose OpenImageIO reader associates alpha), grey →
/// RGB, missing alpha → 255; other PNGs (16-bit, gAMA/iCCP) are converted to 8-bit sRGB by
/// libpng's simplified API. Parse error on anything else, corrupt or truncated data, or a side
/// over kMaxFrameSide. Meant for tests and tools, not the render loop.
Result<Image8> decodeFrame(const std::vector<std::uint8_t>& bytes);

} // namespace dermis
