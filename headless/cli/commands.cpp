#include "headless/cli/commands.h"

#include <cstdio>
#include <functional>

#include <CLI/CLI.hpp>

#include "core/log.h"
#include "headless/cli/options.h"

namespace bb::cli {

int run(int argc, char** argv) {
    CLI::App app{"bundlebake: diffuse global illumination into light maps by ray-bundle tracing on OpenGL 4.3"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Show help for every command");
    bool verbose = false, quiet = false;
    app.add_flag("-v,--verbose", verbose, "Log debug messages");
    app.add_flag("-q,--quiet", quiet, "Only log errors");

    // Each command registers its subcommand and sets `action` when parsed.
    std::function<int()> action;
    addInfoCommand(app, action);
    addBakeCommand(app, action);
    addImportanceCommand(app, action);
    addRenderCommand(app, action);
    addReferenceCommand(app, action);
    addCompareCommand(app, action);
    addExportCommand(app, action);
    addCheckCommand(app, action);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::fprintf(stderr, "bundlebake: error: %s (see --help)\n", e.what());
        return 2;
    }
    setLogLevel(quiet ? LogLevel::Error : verbose ? LogLevel::Debug : LogLevel::Info);
    return action ? action() : 2;
}

}  // namespace bb::cli
