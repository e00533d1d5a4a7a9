// Dermis core — error policy of the core layer.
//
// Every fallible core function returns Result<T>: either a value or an Error. Errors never
// throw across the core's public API. An Error's message names the function that failed and,
// where one input field is to blame, the field by JSON pointer ("/placements/3/theta_max") or by
// name ("theta_max"); `field` repeats that pointer so that shells (CLI, HTTP) can map it without
// parsing text. The HTTP layer maps `code` to a status in one place.
#pragma once

#include <cassert>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace dermis {

/// Error codes of the core. Stable strings: the HTTP layer maps them to statuses.
enum class ErrorCode {
    InvalidArgument, ///< a value is out of range, NaN, of the wrong type or missing
    NotFound,        ///< a named thing (joint, pattern, clip, file) does not exist
    Parse,           ///< bytes could not be decoded (JSON, glTF, image)
    Io,              ///< a file could not be read or written
    Unsupported,     ///< valid input that this version does not handle
    Conflict,        ///< the request conflicts with current state (delete of a model in use)
    StaleRevision,   ///< an edit based on a revision that is no longer current (If-Match)
    TooLarge,        ///< a body, image or size exceeds a configured limit
    Unavailable,     ///< a needed resource cannot be had now (no GL backend starts, queue full)
    Internal,        ///< a failure of a lower layer that is not the caller's fault (GL errors)
    MissingContent,  ///< content named by hash ("sha256:<hex>") that this process does not hold
    Gone,            ///< a thing that existed and was dropped for good (a revision past the history retention)
};

const char* errorCodeName(ErrorCode code);

struct Error {
    ErrorCode code = ErrorCode::InvalidArgument;
    std::string message; ///< "dermis::function: field: what is wrong"
    std::string field;   ///< JSON pointer or field name; empty when no single field is to blame
    /// ErrorCode::StaleRevision only: the revision that is current now.
    std::optional<std::uint64_t> currentRevision;
    /// ErrorCode::MissingContent only: the content addresses ("sha256:<hex>") that are lacking.
    std::vector<std::string> missing;
};

/// Builds an Error whose message is "<where>: <field>: <what>" (field part omitted when empty).
Error makeError(ErrorCode code, const std::string& where, const std::string& field,
                const std::string& what);

/// Value-or-error, in the spirit of std::expected (C++23). Accessing value() of an error (or
/// error() of a value) is a precondition violation (asserts in debug builds).
template <class T> class [[nodiscard]] Result {
public:
    Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}
    Result(Error error) : v_(std::in_place_index<1>, std::move(error)) {}

    bool ok() const { return v_.index() == 0; }
    explicit operator bool() const { return ok(); }

    T& value() & { assert(ok()); return std::get<0>(v_); }
    const T& value() const& { assert(ok()); return std::get<0>(v_); }
    T&& value() && { assert(ok()); return std::get<0>(std::move(v_)); }
    const Error& error() const { assert(!ok()); return std::get<1>(v_); }

    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }

private:
    std::variant<T, Error> v_;
};

struct Ok {};
/// Result of an operation that returns nothing but may fail.
using Status = Result<Ok>;

} // namespace dermis
