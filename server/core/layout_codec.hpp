// Dermis core — a texture layout as bytes, for the data folder's cache of generated layouts
// (SPEC §8: "cached per model (in memory and in the data folder)"), and the content key such a
// cache is addressed by.
//
// Format (little-endian): "DMLY", u32 version (1), u32 kind length + kind bytes, u32 part count,
// then per part: u32 vertex count, that many u32 `source` and 2·f32 `uvs`, u32 index count and
// that many u32 indices. Pure (no file I/O: the service reads and writes the bytes).
#pragma once

#include "model.hpp"
#include "result.hpp"
#include "texture_layout.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dermis {

/// The bytes of `layout` (format above). Deterministic.
std::vector<std::uint8_t> encodeTextureLayout(const TextureLayout& layout);

/// Reads bytes written by encodeTextureLayout and checks them against `model`: one part per model
/// part, each part's index count 0 or that part's, every index below its vertex count, every
/// `source` below the part's position count, every UV finite. Fails (Parse, naming the offset or
/// part) on anything else: a damaged or stale cache file is rebuilt, never trusted.
Result<TextureLayout> decodeTextureLayout(const std::vector<std::uint8_t>& bytes, const Model& model);

/// A 32-hex-digit key of what a layout generator reads from a model (every part's positions,
/// normals, UVs and indices) together with `salt` (the generator's version and options): equal
/// keys mean the same generated layout. Not a cryptographic hash (two 64-bit FNV-1a lanes).
std::string layoutContentKey(const Model& model, std::string_view salt);

} // namespace dermis
