// footfall: footstep placement on uneven terrain, from the command line.
#include <csignal>

#include <CLI/CLI.hpp>

#include "commands.h"

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a vanished server must give an error, not kill us
  CLI::App app{"footfall: places footsteps of bipeds and multipeds on uneven terrain"};
  app.require_subcommand(1);
  int exit_code = 0;
  footfall::cli::AddQueryCommand(app, &exit_code);
  footfall::cli::AddTerrainCommand(app, &exit_code);
  footfall::cli::AddGenerateCommand(app, &exit_code);
  footfall::cli::AddBenchCommand(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return exit_code;
}
