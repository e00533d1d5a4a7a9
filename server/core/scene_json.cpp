// Dermis core — the helpers of scene_json.hpp shared by the scene document and the pattern
// manifest: strict UTF-8, type names and format error codes, JSON pointers (member, and the
// public jsonPointerEscape of scene.hpp), named axes.
#include "scene_json.hpp"

#include <cstdint>

namespace dermis {
namespace scene_detail {

/// Strict UTF-8 (no overlongs, no surrogates, ≤ U+10FFFF). Text parsed by nlohmann is already
/// valid; this guards documents built in code from raw bytes, which dump() would throw on.
bool validUtf8(std::string_view s) {
    std::size_t i = 0;
    while (i < s.size()) {
        const auto c = static_cast<unsigned char>(s[i]);
        std::size_t n = 0;
        std::uint32_t cp = 0;
        if (c < 0x80) {
            ++i;
            continue;
        } else if ((c & 0xE0) == 0xC0) {
            n = 1;
            cp = c & 0x1Fu;
        } else if ((c & 0xF0) == 0xE0) {
            n = 2;
            cp = c & 0x0Fu;
        } else if ((c & 0xF8) == 0xF0) {
            n = 3;
            cp = c & 0x07u;
        } else {
            return false;
        }
        if (i + n >= s.size()) return false; // truncated sequence
        for (std::size_t k = 1; k <= n; ++k) {
            const auto cc = static_cast<unsigned char>(s[i + k]);
            if ((cc & 0xC0) != 0x80) return false;
            cp = (cp << 6) | (cc & 0x3Fu);
        }
        static constexpr std::uint32_t kMin[4] = {0, 0x80, 0x800, 0x10000};
        if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
        i += n + 1;
    }
    return true;
}

std::string describeType(const json& v) {
    return v.type_name();
}

/// Another version of our own format is valid input this build does not handle (Unsupported);
/// anything else in "format" is simply wrong (InvalidArgument).
ErrorCode formatErrorCode(const std::string& got, std::string_view family) {
    return got.rfind(family, 0) == 0 ? ErrorCode::Unsupported : ErrorCode::InvalidArgument;
}

/// Joins a pointer and a member name (escaped).
std::string member(const std::string& ptr, const std::string& key) {
    return ptr + "/" + jsonPointerEscape(key);
}
std::string member(const std::string& ptr, std::size_t index) {
    return ptr + "/" + std::to_string(index);
}

// --- axis ---------------------------------------------------------------------------------------

/// "x" | "y" | "z" → unit vector; nullopt otherwise.
std::optional<std::array<double, 3>> namedAxis(std::string_view name) {
    if (name == "x") return std::array<double, 3>{1, 0, 0};
    if (name == "y") return std::array<double, 3>{0, 1, 0};
    if (name == "z") return std::array<double, 3>{0, 0, 1};
    return std::nullopt;
}

} // namespace scene_detail

std::string jsonPointerEscape(const std::string& token) {
    std::string out;
    out.reserve(token.size());
    for (char c : token) {
        if (c == '~')
            out += "~0";
        else if (c == '/')
            out += "~1";
        else
            out += c;
    }
    return out;
}

} // namespace dermis
