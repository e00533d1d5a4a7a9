// multipart/mixed, incrementally: a small state machine over a buffer of the unread bytes.
#include "multipart.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>

namespace dermis::cli {

MultipartReader::MultipartReader(std::string boundary, PartHandler onPart)
    : boundary_("--" + std::move(boundary)), onPart_(std::move(onPart)) {}

std::string MultipartReader::boundaryOf(const std::string& contentType) {
    const auto at = contentType.find("boundary=");
    if (at == std::string::npos) return "";
    std::string b = contentType.substr(at + 9);
    if (auto semi = b.find(';'); semi != std::string::npos) b.resize(semi);
    if (b.size() >= 2 && b.front() == '"' && b.back() == '"') b = b.substr(1, b.size() - 2);
    return b;
}

bool MultipartReader::fail(const std::string& why) {
    error_ = "malformed multipart answer: " + why;
    state_ = State::Failed;
    return false;
}

bool MultipartReader::feed(const char* data, std::size_t size) {
    if (state_ == State::Done || state_ == State::Failed) return false;
    buffer_.append(data, size);
    while (step()) {
    }
    return state_ != State::Done && state_ != State::Failed;
}

// One transition when the buffer holds enough; false when more bytes are needed (or the end).
bool MultipartReader::step() {
    switch (state_) {
    case State::Preamble:
    case State::AfterBody: {
        const auto eol = buffer_.find("\r\n");
        if (eol == std::string::npos) return false;
        std::string line = buffer_.substr(0, eol);
        buffer_.erase(0, eol + 2);
        if (line.empty() && state_ == State::AfterBody) return true; // the CRLF after a body
        if (line == boundary_ + "--") {
            state_ = State::Done;
            return false;
        }
        if (line == boundary_) {
            headers_.clear();
            length_ = -1;
            state_ = State::Headers;
            return true;
        }
        if (state_ == State::AfterBody) return fail("expected a boundary, got \"" + line.substr(0, 40) + "\"");
        return true; // preamble text
    }
    case State::Headers: {
        const auto eol = buffer_.find("\r\n");
        if (eol == std::string::npos) return false;
        std::string line = buffer_.substr(0, eol);
        buffer_.erase(0, eol + 2);
        if (line.empty()) {
            if (auto it = headers_.find("content-length"); it != headers_.end())
                length_ = std::atoll(it->second.c_str());
            state_ = State::Body;
            return true;
        }
        const auto colon = line.find(':');
        if (colon == std::string::npos) return fail("header without ':'");
        std::string name = line.substr(0, colon);
        std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        std::string value = line.substr(colon + 1);
        value.erase(0, value.find_first_not_of(" \t"));
        headers_[name] = value;
        return true;
    }
    case State::Body: {
        std::string body;
        if (length_ >= 0) {
            if (buffer_.size() < static_cast<std::size_t>(length_)) return false;
            body = buffer_.substr(0, static_cast<std::size_t>(length_));
            buffer_.erase(0, static_cast<std::size_t>(length_));
        } else {
            const auto end = buffer_.find("\r\n" + boundary_);
            if (end == std::string::npos) return false;
            body = buffer_.substr(0, end);
            buffer_.erase(0, end);
        }
        state_ = State::AfterBody;
        if (!onPart_(headers_, std::move(body))) {
            state_ = State::Done;
            return false;
        }
        return true;
    }
    case State::Done:
    case State::Failed:
        return false;
    }
    return false;
}

} // namespace dermis::cli
