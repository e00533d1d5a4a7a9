// Tables, JSON and the progress line.
#include "output.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace dermis::cli {

void printJson(const nlohmann::json& j) { std::cout << j.dump(2) << "\n"; }

std::string cell(const nlohmann::json& j) {
    if (j.is_null()) return "-";
    if (j.is_string()) return j.get<std::string>();
    if (j.is_boolean()) return j.get<bool>() ? "yes" : "no";
    return j.dump();
}

void printTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
    std::vector<std::size_t> width(header.size(), 0);
    auto measure = [&](const std::vector<std::string>& row) {
        for (std::size_t c = 0; c < row.size() && c < width.size(); ++c) width[c] = std::max(width[c], row[c].size());
    };
    measure(header);
    for (const auto& r : rows) measure(r);
    auto print = [&](const std::vector<std::string>& row) {
        std::string line;
        for (std::size_t c = 0; c < row.size() && c < width.size(); ++c) {
            line += row[c];
            if (c + 1 < row.size()) line += std::string(width[c] - row[c].size() + 2, ' ');
        }
        std::cout << line << "\n";
    };
    print(header);
    for (const auto& r : rows) print(r);
}

bool stdoutIsTerminal() { return ::isatty(STDOUT_FILENO) == 1; }

Progress::Progress(std::string what, std::size_t total, bool terminal, bool lines)
    : what_(std::move(what)), total_(total), terminal_(terminal), lines_(lines), start_(std::chrono::steady_clock::now()) {}

double Progress::seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double Progress::rate() const {
    const double s = seconds();
    return s > 0 ? static_cast<double>(done_) / s : 0.0;
}

void Progress::step(const std::string& line, bool failed) {
    ++done_;
    if (failed) ++failed_;
    if (!terminal_) {
        if (lines_) std::cout << line << "\n" << std::flush;
        return;
    }
    // Redraw at most 20 times a second, and always for the last step.
    const auto now = std::chrono::steady_clock::now();
    if (done_ == total_ || !drawn_ || now - lastDraw_ > std::chrono::milliseconds(50)) {
        lastDraw_ = now;
        draw();
    }
}

void Progress::note(const std::string& line) {
    // On stderr, above the redrawn line (which is drawn again with the next step).
    if (terminal_ && drawn_) std::cout << "\r\033[K" << std::flush;
    std::cerr << "dermis: " << line << "\n" << std::flush;
    drawn_ = false;
}

void Progress::draw() {
    const double r = rate();
    char buf[200];
    const double eta = r > 0 ? static_cast<double>(total_ - std::min(done_, total_)) / r : 0.0;
    std::snprintf(buf, sizeof buf, "\r%zu/%zu %s  %.1f %s/s  ETA %.0f s%s", done_, total_, what_.c_str(), r,
                  what_.c_str(), std::ceil(eta), failed_ ? ("  " + std::to_string(failed_) + " failed").c_str() : "");
    std::cout << buf << "\033[K" << std::flush;
    drawn_ = true;
}

void Progress::finish() {
    if (terminal_ && drawn_) {
        draw();
        std::cout << "\n" << std::flush;
    }
}

} // namespace dermis::cli
