// Dermis io shell — the one way Dermis writes a file: whole or not at all.
//
// writeFileAtomically puts the bytes in a fresh temporary file beside the target (its name holds
// kTempMarker), then renames it over the target, so a reader sees the old file or the new one,
// never a partial one. With Durability::Durable the temporary file is fsync'd before the rename
// and the folder after it, so that an acknowledged write survives a crash or kill -9 (the store's
// edits); Durability::Atomic skips both fsyncs (frames and maps written by the offline commands).
//
// A crash between create and rename leaves a temporary file behind; whoever owns the folder
// removes names for which isTempName holds (Store::open does, for the data folder).
//
// Dermis writes no other temporary file: images are decoded from memory (image_io.hpp), so
// nothing goes to the system temp folder.
//
// Thread-safe. Does not create folders. Failure: a file that cannot be created, written, synced
// or renamed → ErrorCode::Io naming `where` with the target path as `field`; the temporary file
// is removed and the target left as it was.
#pragma once

#include "core/result.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dermis {

/// The part of every temporary file name made here: "<target>.tmp.<pid>.<n>".
constexpr const char* kTempMarker = ".tmp.";

/// True when a file or folder name (not a path) is a temporary name left by an interrupted
/// write: it contains kTempMarker.
bool isTempName(const std::string& fileName);

enum class Durability {
    Atomic,  ///< temp file + rename: readers never see a partial file
    Durable, ///< Atomic + fsync of the file before and of its folder after the rename
};

/// Replaces `path` by `bytes` as described above; a symbolic link at `path` is replaced, not
/// followed. New files get mode 0666 minus the process umask.
Status writeFileAtomically(const std::string& path, const std::vector<std::uint8_t>& bytes,
                           Durability durability = Durability::Atomic,
                           const char* where = "dermis::writeFileAtomically");

/// fsyncs a folder (after a rename or removal inside it). Io error naming `where` and the folder.
Status syncFolder(const std::string& folder, const char* where = "dermis::syncFolder");

/// Reads a whole regular file. NotFound when it does not exist, Io when it cannot be read,
/// TooLarge when it is larger than `maxBytes`.
Result<std::vector<std::uint8_t>> readWholeFile(const std::string& path,
                                                std::size_t maxBytes = std::size_t(1) << 32,
                                                const char* where = "dermis::readWholeFile");

} // namespace dermis
