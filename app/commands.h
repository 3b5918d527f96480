// The `ember` subcommands. Each registers its options on a CLI11 subcommand and returns the
// function that runs it; the function returns the process exit code.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace ember::cli {

using Runner = std::function<int()>;

Runner addRenderCommand(CLI::App& app);
Runner addTonemapCommand(CLI::App& app);
Runner addInfoCommand(CLI::App& app);
Runner addBenchCommand(CLI::App& app);
Runner addCompareCommand(CLI::App& app);
Runner addMergeCommand(CLI::App& app);
Runner addDenoiseCommand(CLI::App& app);

}  // namespace ember::cli
