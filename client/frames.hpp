// dermis (client) — frame ranges, frame file names and atomic file writes.
// parseFrameRange and framePath follow `dermis-server render --frames` exactly (same times, same
// names), so the client and the offline command write the same files.
#pragma once

#include <string>
#include <vector>

namespace dermis::cli {

/// "A:B:STEP" in seconds → A, A+STEP, … ≤ B (inclusive within rounding). CliError exit 2 (field
/// `field`) on a malformed range, A < 0, B < A, STEP ≤ 0 or more than 100,000 frames.
std::vector<double> parseFrameRange(const std::string& spec, const std::string& field);

/// `pattern` with its first printf-style integer field (%d, %04d) replaced by `index`; the
/// pattern unchanged when it has none.
std::string framePath(const std::string& pattern, int index);

/// "png" or "jpeg" from a file name (.png, .jpg, .jpeg; case-insensitive), "" otherwise.
std::string imageFormatOf(const std::string& path);

/// The lower-cased extension without the dot ("" when none).
std::string extensionOf(const std::string& path);

/// Writes `bytes` to `path` atomically: to "<path>.dermis-part" in the same folder (created if
/// needed), then renamed over `path`, so `path` is either absent, its old content, or complete.
/// CliError exit 2 (field = path) when the folder or file cannot be written; the temporary file
/// is removed on failure.
void writeFileAtomically(const std::string& path, const std::string& bytes);

/// Writes all `n` bytes to the open descriptor `fd` (retrying short writes and EINTR). False on a
/// write error (errno says which); the descriptor stays open either way.
bool writeAll(int fd, const char* data, std::size_t n);

/// The temporary name writeFileAtomically uses for `path`.
std::string partialPathOf(const std::string& path);

} // namespace dermis::cli
