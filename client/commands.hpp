// dermis (client) — the subcommand families. Each add* function registers its subcommands (with
// their options and --help) on the app; a subcommand's callback sets ctx.action, which main runs.
#pragma once

#include "context.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>

namespace dermis::cli {

void addSystemCommands(CLI::App& app, Context& ctx);  ///< health, info, lint, watch
void addModelCommands(CLI::App& app, Context& ctx);   ///< model …, pattern …
void addSceneCommands(CLI::App& app, Context& ctx);   ///< scene …, pose set, placement …
void addRenderCommands(CLI::App& app, Context& ctx);  ///< frame, maps, render
void addCheckCommand(CLI::App& app, Context& ctx);    ///< check

/// A scene document from a file ("-" = stdin): CliError exit 2 (field `field`) when unreadable or
/// not a JSON object.
nlohmann::json readJsonFile(const std::string& path, const std::string& field);

/// "/scenes/<id>" with the id percent-encoded.
std::string scenePath(const std::string& id);

} // namespace dermis::cli
