// Dermis core — private to server/core/scene*.cpp: the typed JSON reader and the predicates that
// the scene document (scene_parse.cpp), the pattern manifest (scene_manifest.cpp) and the scene
// serialiser (scene.cpp) share. Not included by any public header.
//
// Every reader takes the value and the RFC 6901 pointer of where it sits in the document, so that
// whatever fails can name the field ("/placements/3/theta_max") in Error::field; errors carry the
// `where` the Reader was made with (the public function). Nothing here throws or aborts on bad
// input: values are type-checked before nlohmann's get<> reads them.
#pragma once

#include "scene.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

namespace dermis {

using json = nlohmann::json;

namespace scene_detail {

inline constexpr const char* kSceneFormat = "dermis.scene/1";

/// Ids end up in URLs (/scenes/{id}/placements/{pid}) and file names; keep them short.
inline constexpr std::size_t kMaxIdLength = 128;
inline constexpr std::size_t kMaxPathLength = 4096;

// --- small predicates -------------------------------------------------------------------------

/// Strict UTF-8 (no overlongs, no surrogates, ≤ U+10FFFF).
bool validUtf8(std::string_view s);

/// The JSON type of `v` for messages ("object", "number", …).
std::string describeType(const json& v);

/// Another version of our own format (`got` starts with `family`) is valid input this build does
/// not handle (Unsupported); anything else in "format" is simply wrong (InvalidArgument).
ErrorCode formatErrorCode(const std::string& got, std::string_view family);

// --- the reader: typed access with pointer-named errors ----------------------------------------

class Reader {
  public:
    explicit Reader(const char* where) : where_(where) {}

    Error bad(const std::string& ptr, const std::string& what,
              ErrorCode code = ErrorCode::InvalidArgument) const {
        return makeError(code, where_, ptr, what);
    }

    /// The member `key` of object `obj`, or nullptr when absent.
    static const json* find(const json& obj, const char* key) {
        auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }

    Status object(const json& v, const std::string& ptr) const {
        if (!v.is_object()) return bad(ptr, "expected an object, got " + describeType(v));
        return Ok{};
    }

    Status array(const json& v, const std::string& ptr) const {
        if (!v.is_array()) return bad(ptr, "expected an array, got " + describeType(v));
        return Ok{};
    }

    /// A finite number (booleans and null are not numbers).
    Result<double> number(const json& v, const std::string& ptr) const {
        if (!v.is_number()) return bad(ptr, "expected a number, got " + describeType(v));
        const double d = v.get<double>();
        if (!std::isfinite(d)) return bad(ptr, "must be a finite number");
        return d;
    }

    /// A finite number ≥ lo (and ≤ hi).
    Result<double> numberIn(const json& v, const std::string& ptr, double lo,
                            double hi = std::numeric_limits<double>::infinity()) const {
        auto d = number(v, ptr);
        if (!d) return d;
        if (*d < lo || *d > hi) {
            std::string range = std::isinf(hi) ? "must be >= " + fmt(lo)
                                               : "must be in [" + fmt(lo) + ", " + fmt(hi) + "]";
            return bad(ptr, range + ", got " + fmt(*d));
        }
        return d;
    }

    /// An integral number in [lo, hi]. 512.0 is accepted (it is an integer), 10.5 is not.
    Result<int> integer(const json& v, const std::string& ptr, int lo, int hi) const {
        if (!v.is_number()) return bad(ptr, "expected an integer, got " + describeType(v));
        const double d = v.get<double>();
        if (!std::isfinite(d) || d != std::floor(d)) return bad(ptr, "must be an integer");
        if (d < lo || d > hi)
            return bad(ptr, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                "], got " + fmt(d));
        return static_cast<int>(d);
    }

    Result<std::string> string(const json& v, const std::string& ptr, bool nonEmpty = true) const {
        if (!v.is_string()) return bad(ptr, "expected a string, got " + describeType(v));
        const auto& s = v.get_ref<const std::string&>();
        if (nonEmpty && s.empty()) return bad(ptr, "must not be empty");
        if (!validUtf8(s)) return bad(ptr, "must be valid UTF-8");
        return s;
    }

    /// A string naming an enumerator: `parse` maps it (std::optional), `choices` lists the
    /// accepted spellings for the message.
    template <class Parse>
    auto enumeration(const json& v, const std::string& ptr, Parse parse, const char* choices) const
        -> Result<typename decltype(parse(std::string_view{}))::value_type> {
        auto s = string(v, ptr);
        if (!s) return s.error();
        auto e = parse(*s);
        if (!e) return bad(ptr, std::string("must be ") + choices + ", got '" + *s + "'");
        return *e;
    }

    /// A file path or reference: a non-empty string without NUL bytes, of sane length.
    Result<std::string> path(const json& v, const std::string& ptr) const {
        auto s = string(v, ptr);
        if (!s) return s;
        if (s->size() > kMaxPathLength) return bad(ptr, "is too long");
        if (s->find('\0') != std::string::npos) return bad(ptr, "must not contain NUL characters");
        return s;
    }

    /// An array of exactly N finite numbers; an element's error names the element.
    template <std::size_t N>
    Result<std::array<double, N>> numbers(const json& v, const std::string& ptr) const {
        if (!v.is_array())
            return bad(ptr, "expected an array of " + std::to_string(N) + " numbers, got " +
                                describeType(v));
        if (v.size() != N)
            return bad(ptr, "must have exactly " + std::to_string(N) + " elements, got " +
                                std::to_string(v.size()));
        std::array<double, N> out{};
        for (std::size_t i = 0; i < N; ++i) {
            auto d = number(v[i], ptr + "/" + std::to_string(i));
            if (!d) return d.error();
            out[i] = *d;
        }
        return out;
    }

    /// [w, h], each an integer in [lo, hi].
    Result<std::array<int, 2>> size(const json& v, const std::string& ptr, int lo, int hi) const {
        if (!v.is_array())
            return bad(ptr, "expected an array [width, height], got " + describeType(v));
        if (v.size() != 2)
            return bad(ptr, "must have exactly 2 elements, got " + std::to_string(v.size()));
        std::array<int, 2> out{};
        for (std::size_t i = 0; i < 2; ++i) {
            auto n = integer(v[i], ptr + "/" + std::to_string(i), lo, hi);
            if (!n) return n.error();
            out[i] = *n;
        }
        return out;
    }

    /// Shortest text that reads back as `d`; integral values without a trailing ".0".
    static std::string fmt(double d) {
        if (std::isfinite(d) && d == std::floor(d) && std::abs(d) < 1e15)
            return std::to_string(static_cast<long long>(d));
        return json(d).dump();
    }

  private:
    const char* where_;
};

/// Joins a pointer and a member name (escaped) or an array index.
std::string member(const std::string& ptr, const std::string& key);
std::string member(const std::string& ptr, std::size_t index);

/// "x" | "y" | "z" → unit vector; nullopt otherwise.
std::optional<std::array<double, 3>> namedAxis(std::string_view name);

} // namespace scene_detail
} // namespace dermis
