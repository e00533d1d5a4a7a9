// dermis (client) — an incremental reader of a multipart/mixed answer (the batch route POST
// /render): bytes are fed as they arrive; each complete part is handed over with its headers.
// A part with Content-Length is cut by its length (the frames); one without it (the JSON error
// part) ends at the next boundary line. Malformed input sets error() and stops taking bytes.
#pragma once

#include <functional>
#include <map>
#include <string>

namespace dermis::cli {

class MultipartReader {
public:
    /// Header names are lower-cased. Return false from onPart to stop.
    using PartHandler = std::function<bool(const std::map<std::string, std::string>& headers, std::string body)>;

    MultipartReader(std::string boundary, PartHandler onPart);
    /// Takes the next bytes; false once finished, stopped by the handler, or malformed.
    bool feed(const char* data, std::size_t size);
    bool finished() const { return state_ == State::Done; }
    const std::string& error() const { return error_; }

    /// The boundary parameter of a Content-Type ("" when none).
    static std::string boundaryOf(const std::string& contentType);

private:
    enum class State { Preamble, Headers, Body, AfterBody, Done, Failed };
    bool step();
    bool fail(const std::string& why);

    std::string boundary_, buffer_, error_;
    PartHandler onPart_;
    State state_ = State::Preamble;
    std::map<std::string, std::string> headers_;
    long long length_ = -1;
};

} // namespace dermis::cli
