// dermis (client) — what the client prints: the server's JSON (--json), short human tables, and
// the progress of long commands (render, check): on a terminal one line redrawn with '\r'
// (done/total, frames/s, ETA); when stdout is not a terminal, plain log lines, one per step.
// Writes to stdout; messages for people go to stderr only for errors (main).
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <string>
#include <vector>

namespace dermis::cli {

/// The JSON, indented by 2, and a newline.
void printJson(const nlohmann::json& j);

/// Columns padded to their widest cell, a header row first (no borders).
void printTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);

/// A JSON value as a table cell: strings bare, numbers shortest, null as "-".
std::string cell(const nlohmann::json& j);

/// True when stdout is a terminal.
bool stdoutIsTerminal();

class Progress {
public:
    /// `what` names the steps ("frames", "cases"); `terminal` picks the redrawn line; `lines`
    /// false prints no step lines either (--json).
    Progress(std::string what, std::size_t total, bool terminal, bool lines = true);
    /// One more step done; `line` is the log line printed when not on a terminal.
    void step(const std::string& line, bool failed = false);
    /// A line that is not a step (a retry): on stderr as "dermis: <line>".
    void note(const std::string& line);
    /// Ends the redrawn line (a newline) — call once at the end, also after an interruption.
    void finish();
    std::size_t done() const { return done_; }
    double seconds() const;
    /// done / seconds.
    double rate() const;

private:
    void draw();
    std::string what_;
    std::size_t total_, done_ = 0, failed_ = 0;
    bool terminal_, lines_ = true, drawn_ = false;
    std::chrono::steady_clock::time_point start_, lastDraw_;
};

} // namespace dermis::cli
