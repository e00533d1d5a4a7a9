// dermis (client) — what every subcommand shares: the global options (server, token, timeouts,
// retries, --json), the exit codes, the error every failure is reported with, and the Ctrl-C
// flag. Subcommands register on the CLI11 app and set Context::action; main runs it once the
// command line parsed.
//
// Failures are thrown as CliError (exit code, message, field) and caught in main, which prints
// `dermis: error: <message> (<field>)` on stderr and exits with the code. Nothing else throws on
// purpose.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace dermis::cli {

/// The documented exit codes (client/README.md).
enum ExitCode : int {
    kExitOk = 0,
    kExitServerSaidNo = 1, ///< the server answered with an error (4xx/5xx)
    kExitUsage = 2,        ///< bad command line or input file
    kExitCannotConnect = 3,///< no connection, or the connection broke
    kExitFramesFailed = 4, ///< render: some frames failed; check: some cases differ
    kExitInterrupted = 130 ///< Ctrl-C (SIGINT): stopped cleanly
};

/// A failure to report: `field` names the option, argument or document member ("" when none).
struct CliError : std::runtime_error {
    CliError(int exitCode, const std::string& message, std::string fieldName = "")
        : std::runtime_error(message), code(exitCode), field(std::move(fieldName)) {}
    int code;
    std::string field;
    int httpStatus = 0;  ///< the server's status when it answered with an error (serverError)
    std::string answer;  ///< and its body
};

/// A usage error (exit 2).
inline CliError usageError(const std::string& message, const std::string& field = "") {
    return CliError(kExitUsage, message, field);
}

struct GlobalOptions {
    std::string server = "http://127.0.0.1:8080"; ///< --server / DERMIS_SERVER
    std::string token;                              ///< --token / DERMIS_TOKEN
    double timeout = 120.0;                         ///< --timeout: seconds per read or connect
    double deadline = 600.0;                        ///< --deadline: seconds per request, whole
    double maxTime = 0.0;                           ///< --max-time: seconds for the command (0: none)
    int retries = 2;                                ///< --retries: idempotent requests only
    bool json = false;                              ///< --json: print the server's JSON
    std::string client;                             ///< --client: X-Dermis-Client of edits
};

class Http;

struct Context {
    GlobalOptions global;
    std::function<int()> action; ///< set by the chosen subcommand's callback
    /// The HTTP client for global.server, made on first use.
    Http& http();

private:
    std::shared_ptr<Http> http_;
};

/// Set by SIGINT (installed by main). Long commands poll it and stop cleanly.
extern std::atomic<bool> g_interrupted;

/// Reads a whole file; CliError (exit 2, field = `what`) when it cannot be read.
std::string readFileOrThrow(const std::string& path, const std::string& what);

} // namespace dermis::cli
