#include "result.hpp"

namespace dermis {

const char* errorCodeName(ErrorCode code) {
    switch (code) {
    case ErrorCode::InvalidArgument: return "invalid_argument";
    case ErrorCode::NotFound: return "not_found";
    case ErrorCode::Parse: return "parse_error";
    case ErrorCode::Io: return "io_error";
    case ErrorCode::Unsupported: return "unsupported";
    case ErrorCode::Conflict: return "conflict";
    case ErrorCode::StaleRevision: return "stale_revision";
    case ErrorCode::TooLarge: return "too_large";
    case ErrorCode::Unavailable: return "unavailable";
    case ErrorCode::Internal: return "internal";
    case ErrorCode::MissingContent: return "missing_content";
    case ErrorCode::Gone: return "gone";
    }
    return "unknown";
}

Error makeError(ErrorCode code, const std::string& where, const std::string& field,
                const std::string& what) {
    Error e;
    e.code = code;
    e.field = field;
    e.message = where + ": " + (field.empty() ? std::string() : field + ": ") + what;
    return e;
}

} // namespace dermis
