// The `footfall` subcommands. Each Add*Command registers its subcommand on `app`; the callback
// it installs stores the process exit code in *exit_code.
#pragma once

#include <CLI/CLI.hpp>

namespace footfall::cli {

void AddQueryCommand(CLI::App& app, int* exit_code);
void AddTerrainCommand(CLI::App& app, int* exit_code);
void AddGenerateCommand(CLI::App& app, int* exit_code);
void AddBenchCommand(CLI::App& app, int* exit_code);

}  // namespace footfall::cli
