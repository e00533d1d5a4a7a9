// dermis — the command-line client of dermis-server (issue #14; usage in client/README.md).
//   dermis [--server URL] [--token T] [--timeout S] [--deadline S] [--max-time S] [--retries N] [--json] <command> …
// Exit codes: 0 ok, 1 the server said no, 2 usage, 3 cannot connect, 4 some frames failed (render)
// or some cases differ (check), 130 interrupted (Ctrl-C: finished files stay, no partial file).
#include "commands.hpp"
#include "context.hpp"

#include <csignal>
#include <cstdlib>
#include <iostream>

namespace {

void onSigint(int) { dermis::cli::g_interrupted = true; }

void installSigint() {
    struct sigaction sa {};
    sa.sa_handler = onSigint;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND; // a second Ctrl-C ends the process at once
    sigaction(SIGINT, &sa, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
}

} // namespace

int main(int argc, char** argv) {
    using namespace dermis::cli;
    Context ctx;
    if (const char* s = std::getenv("DERMIS_SERVER"); s && *s) ctx.global.server = s;
    if (const char* t = std::getenv("DERMIS_TOKEN"); t && *t) ctx.global.token = t;

    CLI::App app{"dermis — command-line client of dermis-server (skin deformation render server)"};
    app.name("dermis");
    app.require_subcommand(1);
    app.fallthrough();
    app.set_version_flag("--version", "dermis 0.1.0");
    app.add_option("--server", ctx.global.server, "Server URL (env DERMIS_SERVER; default http://127.0.0.1:8080)");
    app.add_option("--token", ctx.global.token, "Bearer token (env DERMIS_TOKEN)");
    app.add_option("--timeout", ctx.global.timeout, "Seconds to wait for a connection or a read (default 120)")
        ->check(CLI::PositiveNumber);
    app.add_option("--deadline", ctx.global.deadline, "Seconds one request may take in all, answer included (default 600; event streams: none)")
        ->check(CLI::PositiveNumber);
    app.add_option("--max-time", ctx.global.maxTime, "Seconds the whole command may take (default: no limit)")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--retries", ctx.global.retries, "Retries of idempotent requests on no connection or 503 (default 2)")
        ->check(CLI::Range(0, 100));
    app.add_flag("--json", ctx.global.json, "Print the server's JSON instead of tables");
    app.add_option("--client", ctx.global.client, "X-Dermis-Client name recorded with edits (scene history)");

    addSystemCommands(app, ctx);
    addModelCommands(app, ctx);
    addSceneCommands(app, ctx);
    addRenderCommands(app, ctx);
    addCheckCommand(app, ctx);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "dermis: error: " << e.what() << "\n"
                  << "Run with --help for more information.\n";
        return kExitUsage;
    } catch (const CliError& e) {
        std::cerr << "dermis: error: " << e.what() << (e.field.empty() ? "" : " (" + e.field + ")") << "\n";
        return e.code;
    }
    if (!ctx.action) {
        std::cerr << "dermis: error: no command given\nRun with --help for more information.\n";
        return kExitUsage;
    }
    installSigint();
    try {
        const int code = ctx.action();
        // Commands that do not poll the flag finish their request (and its atomic write) first.
        return g_interrupted && code == kExitOk ? kExitInterrupted : code;
    } catch (const CliError& e) {
        std::cout << std::flush;
        std::cerr << "dermis: error: " << e.what() << (e.field.empty() ? "" : " (" + e.field + ")") << "\n";
        return e.code;
    } catch (const std::exception& e) {
        std::cerr << "dermis: error: " << e.what() << "\n";
        return kExitUsage;
    }
}
