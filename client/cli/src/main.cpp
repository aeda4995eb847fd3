// footfall: footstep placement on uneven terrain, from the command line.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/process_start.h"
#include "footfall/version.h"
#include "standard_streams.h"

namespace {

// What is wrong with the command words of argv (a command missing, or a word or option that
// names none where a command is expected), or "" when CLI11 can take it from there.
std::string CommandHint(const CLI::App& root, int argc, char** argv) {
  const CLI::App* at = &root;
  std::string path = "footfall";
  auto names = [](const CLI::App* app) {
    std::string list;
    for (const CLI::App* command : app->get_subcommands({}))
      list += (list.empty() ? "" : ", ") + command->get_name();
    return list;
  };
  for (int i = 1; i < argc; ++i) {
    const std::vector<const CLI::App*> commands = at->get_subcommands({});
    if (commands.empty()) return "";  // a command's own flags and arguments: CLI11's
    const std::string word = argv[i];
    if (word == "-h" || word == "--help" || (at == &root && word == "--version")) return "";
    if (!word.empty() && word[0] == '-')
      return path + ": unknown option '" + word + "' where a command is expected: " + names(at) +
             " (" + path + " --help)";
    const CLI::App* next = nullptr;
    for (const CLI::App* command : commands)
      if (command->check_name(word)) next = command;
    if (!next)
      return path + ": unknown command '" + word + "': expected one of " + names(at) + " (" + path +
             " --help)";
    at = next;
    path += " " + next->get_name();
  }
  if (at->get_subcommands({}).empty()) return "";
  return path + ": a command is required: " + names(at) + " (" + path + " --help)";
}

// The number of single-character edits (insertions, deletions, substitutions) between a and b.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The long option of `options` that `word` ("--setps", "-steps", "--sep") was most likely meant
// to be, as "--steps"; "" when none is near. Near: at most two edits away (one for names of
// four letters or fewer), or a name the word begins, of three letters or more.
std::string NearestOptionName(const std::vector<const CLI::Option*>& options,
                              const std::string& word) {
  const std::string written = word.substr(word.find_first_not_of('-'));
  std::string best;
  size_t best_distance = 3;
  for (const CLI::Option* o : options) {
    for (const std::string& name : o->get_lnames()) {
      size_t distance = EditDistance(written, name);
      if (name.size() <= 4 && distance > 1) continue;
      if (written.size() >= 3 && name.compare(0, written.size(), written) == 0)
        distance = std::min<size_t>(distance, 2);
      if (distance < best_distance) best = "--" + name, best_distance = distance;
    }
  }
  return best;
}

// An option that takes a value followed by another option instead ("--terrain --character
// c.json"): "footfall generate: --terrain needs a value, found the option --character", or a
// word written as an option that is none of the command's; else "".
// CLI11 takes the next word as the value whatever it is, so "--out --steps" wrote a file named
// "--steps" and the flag was lost. The command words must be valid (CommandHint is "").
std::string MissingValueHint(const CLI::App& root, int argc, char** argv) {
  const CLI::App* at = &root;
  std::string path = "footfall";
  int i = 1;
  for (; i < argc && !at->get_subcommands({}).empty(); ++i) {
    for (const CLI::App* command : at->get_subcommands({}))
      if (command->check_name(argv[i])) at = command;
    path += " " + at->get_name();
  }
  // An option's own name as written (not "--name=value", not a negative number). (Not
  // get_option_no_throw: it is noexcept, and memory running out in it ended the process.)
  const std::vector<const CLI::Option*> options = at->get_options();
  auto option = [&](const std::string& word) -> const CLI::Option* {
    if (word.size() < 2 || word[0] != '-' || word.find('=') != std::string::npos) return nullptr;
    for (const CLI::Option* o : options)
      if (o->check_name(word)) return o;
    return nullptr;
  };
  // A word that is no option of the command though written as one: not a negative number, a
  // short option with its value joined ("-ofile"), nor "--name=value" of a known name.
  auto unknown = [&](const std::string& word) {
    if (word.size() < 2 || word[0] != '-' || word == "-h" || word == "--help") return false;
    if (std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.') return false;
    // A long option written with one dash ("-out walk.json" was -o with the value "ut").
    if (word[1] != '-' && word.size() > 2 && option("-" + word.substr(0, word.find('='))))
      return true;
    if (word[1] != '-' && option(word.substr(0, 2))) return false;
    const size_t equals = word.find('=');
    return !(word[1] == '-' && equals != std::string::npos && option(word.substr(0, equals)));
  };
  // Whether the command takes arguments that are not options (files): a name starting with
  // '-' then goes after '--'.
  const bool positionals = std::any_of(options.begin(), options.end(),
                                       [](const CLI::Option* o) { return !o->nonpositional(); });
  const std::string listed =
      " (" + path + " --help lists them" +
      (positionals ? "; a file whose name starts with '-' goes after '--')" : ")");
  for (; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;  // the rest are arguments, whatever they look like
    // "-o=walk.json": CLI11 takes "=walk.json" as the value, and wrote a file of that name.
    if (word.size() > 2 && word[0] == '-' && word[1] != '-' && word[2] == '=' &&
        option(word.substr(0, 2)))
      return path + ": '" + word + "' would give " + word.substr(0, 2) + " the value '" +
             word.substr(2) + "': write " + word.substr(0, 2) + " " + word.substr(3) +
             " (a space, not '=', after a one-letter option)";
    const CLI::Option* taking = option(word);
    // (A file named "-dash.pts" was "input is required".)
    if (!taking && unknown(word)) {
      const std::string meant = NearestOptionName(options, word);
      return path + ": unknown option '" + word + "'" +
             (meant.empty() ? "" : ": did you mean " + meant + "?") + listed;
    }
    if (!taking || taking->get_items_expected_min() == 0) continue;
    if (i + 1 < argc) {
      const std::string next = argv[i + 1];
      if (option(next) || next == "-h" || next == "--help")
        return path + ": " + word + " needs a value, found the option " + next + " (" + path +
               " --help)";
    }
    i += taking->get_items_expected_min();  // its values are not options to check
  }
  return "";
}

// The command line's work; its exit status.
int Run(int argc, char** argv) {
  // No output file may take descriptor 1 or 2; non-blocking streams are waited for, not failed.
  footfall::cli::UseWaitingStandardStreams(footfall::OpenClosedStandardStreams());
  std::signal(SIGPIPE, SIG_IGN);            // a vanished server must give an error, not kill us
  footfall::RemoveTemporaryFileOnSignal();  // an interrupted write leaves no temporary file
  CLI::App app{"footfall: places footsteps of bipeds and multipeds on uneven terrain"};
  app.require_subcommand(1);
  // `footfall --version`: "footfall 0.1.0" on stdout, exit 0 (footfall/version.h).
  app.set_version_flag("--version", "footfall " FOOTFALL_VERSION,
                       "Print footfall's version and exit");
  int exit_code = 0;
  footfall::cli::AddQueryCommand(app, &exit_code);
  footfall::cli::AddTerrainCommand(app, &exit_code);
  footfall::cli::AddGenerateCommand(app, &exit_code);
  footfall::cli::AddBenchCommand(app, &exit_code);
  // `footfall help [COMMAND...]` is `footfall [COMMAND...] --help`, as git and cargo take it.
  std::vector<char*> args(argv, argv + argc);
  static char help_flag[] = "--help";
  if (argc >= 2 && std::string(argv[1]) == "help") {
    args.erase(args.begin() + 1);
    args.push_back(help_flag);
    argc = static_cast<int>(args.size());
    argv = args.data();
  }
  // No command, or a word that names none: say which there are (CLI11 only says that one is
  // required).
  std::string hint = CommandHint(app, argc, argv);
  if (hint.empty()) hint = MissingValueHint(app, argc, argv);
  if (!hint.empty()) {
    std::cerr << hint << '\n';
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
  } catch (const std::system_error& e) {
    // std::thread's failure to start one (ulimit -u, or memory for its stack).
    std::cerr << "footfall: " << footfall::SystemErrorText(e) << '\n';
    return 1;
  } catch (const std::exception& e) {
    // A last resort: every reader reports bad input as a message of its own; whatever escapes
    // them still ends in a message and exit status 1, never an abort.
    std::cerr << "footfall: " << e.what() << '\n';
    return 1;
  }
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  int status = 1;
  try {
    status = Run(argc, argv);
  } catch (const std::bad_alloc&) {
    // Memory ran out setting the command line up (Run's own try covers the command's work).
    std::fputs("footfall: out of memory\n", stderr);
    return 1;
  }
  // Output that could not be written (a full disk, a closed pipe) fails the command: `bench
  // --json > file` on a full disk left an empty file and exit 0. (`query` says so itself.)
  std::cout.flush();
  if (!std::cout && status == 0) {
    const int why = footfall::cli::StandardOutputError();
    std::cerr << "footfall: cannot write standard output"
              << (why ? std::string(": ") + std::strerror(why) : std::string()) << '\n';
    return 1;
  }
  return status;
}
