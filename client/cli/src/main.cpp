// footfall: footstep placement on uneven terrain, from the command line.
#include <csignal>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "footfall/terrain/output_file.h"

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);            // a vanished server must give an error, not kill us
  footfall::RemoveTemporaryFileOnSignal();  // an interrupted write leaves no temporary file
  CLI::App app{"footfall: places footsteps of bipeds and multipeds on uneven terrain"};
  app.require_subcommand(1);
  int exit_code = 0;
  footfall::cli::AddQueryCommand(app, &exit_code);
  footfall::cli::AddTerrainCommand(app, &exit_code);
  footfall::cli::AddGenerateCommand(app, &exit_code);
  footfall::cli::AddBenchCommand(app, &exit_code);
  // No command, or a word that names none: say which there are (CLI11 only says that one is
  // required).
  std::string names;
  bool known = false;
  for (const CLI::App* command : app.get_subcommands({})) {
    names += (names.empty() ? "" : ", ") + command->get_name();
    known |= argc >= 2 && command->check_name(argv[1]);
  }
  if (argc < 2 || (argv[1][0] != '-' && !known)) {
    if (argc < 2)
      std::cerr << "footfall: a command is required: " << names << " (footfall --help)\n";
    else
      std::cerr << "footfall: unknown command '" << argv[1] << "': expected one of " << names
                << " (footfall --help)\n";
    return 1;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 prints the message; every refused flag exits 1, as other bad input does (--help 0).
    return app.exit(e) == 0 ? 0 : 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "footfall: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    // A last resort: every reader reports bad input as a message of its own; whatever escapes
    // them still ends in a message and exit status 1, never an abort.
    std::cerr << "footfall: " << e.what() << '\n';
    return 1;
  }
  return exit_code;
}
