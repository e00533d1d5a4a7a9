#include "core/frame_range.hpp"

#include <charconv>
#include <cmath>
#include <string>

namespace dermis {
namespace {

const char* kWhere = "dermis::FrameRange";

bool parseDouble(std::string_view s, double& out) {
    // std::from_chars for double: no locale, no leading '+', no spaces.
    if (s.empty()) return false;
    const char* end = s.data() + s.size();
    auto r = std::from_chars(s.data(), end, out);
    return r.ec == std::errc() && r.ptr == end;
}

bool parseInt(std::string_view s, long long& out) {
    if (s.empty()) return false;
    const char* end = s.data() + s.size();
    auto r = std::from_chars(s.data(), end, out);
    return r.ec == std::errc() && r.ptr == end;
}

} // namespace

Result<FrameRange> parseFrameRange(std::string_view spec, const std::string& field) {
    const std::string text(spec);
    const auto c1 = spec.find(':');
    const auto c2 = c1 == std::string_view::npos ? c1 : spec.find(':', c1 + 1);
    FrameRange r;
    if (c2 == std::string_view::npos || spec.find(':', c2 + 1) != std::string_view::npos ||
        !parseDouble(spec.substr(0, c1), r.start) ||
        !parseDouble(spec.substr(c1 + 1, c2 - c1 - 1), r.end) ||
        !parseDouble(spec.substr(c2 + 1), r.step))
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "expected A:B:STEP in seconds, got \"" + text + "\"");
    if (!std::isfinite(r.start) || !std::isfinite(r.end) || !std::isfinite(r.step) ||
        r.start < 0 || r.end < r.start || r.step <= 0)
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "need 0 <= A <= B and STEP > 0, got \"" + text + "\"");
    const double n = std::floor((r.end - r.start) / r.step + 1e-9) + 1;
    if (n > kMaxRangeFrames)
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "more than " + std::to_string(kMaxRangeFrames) + " frames");
    r.count = static_cast<int>(n);
    return r;
}

Result<Shard> parseShard(std::string_view spec, const EnvLookup& env, const std::string& field) {
    const std::string text(spec);
    const auto slash = spec.find('/');
    long long n = 0, i = 0;
    if (slash == std::string_view::npos || !parseInt(spec.substr(slash + 1), n))
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "expected I/N or auto/N, got \"" + text + "\"");
    if (n < 1 || n > kMaxRangeFrames)
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "N must be 1 … " + std::to_string(kMaxRangeFrames) + ", got \"" + text + "\"");
    const std::string_view head = spec.substr(0, slash);
    if (head == "auto") {
        const char* names[] = {"SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"};
        const char* value = nullptr;
        const char* from = nullptr;
        for (const char* name : names) {
            if (const char* v = env ? env(name) : nullptr; v && *v) {
                value = v;
                from = name;
                break;
            }
        }
        if (!value)
            return makeError(ErrorCode::InvalidArgument, kWhere, field,
                             "auto/N needs SLURM_ARRAY_TASK_ID (Slurm job array) or "
                             "JOB_COMPLETION_INDEX (Kubernetes Indexed Job); neither is set");
        if (!parseInt(value, i))
            return makeError(ErrorCode::InvalidArgument, kWhere, field,
                             std::string(from) + " is not an integer: \"" + value + "\"");
    } else if (!parseInt(head, i)) {
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "expected I/N or auto/N, got \"" + text + "\"");
    }
    if (i < 0 || i >= n)
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "the shard index " + std::to_string(i) + " is outside 0 … " +
                             std::to_string(n - 1));
    return Shard{static_cast<int>(i), static_cast<int>(n)};
}

std::vector<int> shardFrames(const FrameRange& range, const Shard& shard) {
    std::vector<int> frames;
    if (shard.count < 1 || shard.index < 0 || shard.index >= shard.count) return frames;
    for (int k = shard.index; k < range.count; k += shard.count)
        frames.push_back(k);
    return frames;
}

namespace {

/// The first "%[0][width]d" in `s`: its position and length (npos when there is none).
std::pair<std::size_t, std::size_t> findFrameField(const std::string& s) {
    for (std::size_t i = s.find('%'); i != std::string::npos; i = s.find('%', i + 1)) {
        std::size_t j = i + 1;
        while (j < s.size() && j - i <= 3 && s[j] >= '0' && s[j] <= '9') ++j;
        if (j < s.size() && s[j] == 'd') return {i, j + 1 - i};
    }
    return {std::string::npos, 0};
}

} // namespace

bool hasFrameField(const std::string& pattern) {
    return findFrameField(pattern).first != std::string::npos;
}

std::string framePath(const std::string& pattern, int index) {
    const auto [at, length] = findFrameField(pattern);
    if (at == std::string::npos) return pattern;
    const std::string spec = pattern.substr(at + 1, length - 2); // between '%' and 'd'
    const bool zeros = !spec.empty() && spec[0] == '0';
    const std::size_t width = spec.empty() ? 0 : static_cast<std::size_t>(std::stoi(spec));
    std::string digits = std::to_string(index < 0 ? -static_cast<long long>(index) : index);
    const std::size_t signWidth = index < 0 ? 1 : 0;
    if (digits.size() + signWidth < width)
        digits.insert(0, width - digits.size() - signWidth, zeros ? '0' : ' ');
    if (index < 0) digits.insert(zeros ? 0 : digits.find_first_not_of(' '), 1, '-');
    return pattern.substr(0, at) + digits + pattern.substr(at + length);
}

} // namespace dermis
