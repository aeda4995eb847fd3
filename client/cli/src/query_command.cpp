// `footfall query`: answers snap / normal / next commands read from stdin, one JSON line each.
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "footfall/cli/number_checks.h"
#include "footfall/client/query_text.h"
#include "standard_streams.h"
#include "terrain_flags.h"

namespace footfall::cli {
namespace {

// One stdin line that holds a command.
struct Command {
  size_t line = 0;
  QueryText query;
  std::string error;  // non-empty: the line was malformed
};

// Parses one command line; returns false for blank and comment lines.
// [Units: characters] The longest query line read: the longest valid one is about 200; a longer
// one is an error, read past without being kept (a 200 MB line held 1.4 GB).
constexpr std::streamsize kMaxLine = 4096;

// Reads one line of `in` into *text, at most kMaxLine characters; *too_long when it had more
// (the rest is skipped). False at the end of the input.
bool ReadLine(std::istream& in, std::string* text, bool* too_long) {
  *too_long = false;
  // Room for kMaxLine characters, a CRLF line's CR (not counted: a line of kMaxLine characters
  // ended by CRLF was refused as too long) and the terminating NUL.
  text->resize(static_cast<size_t>(kMaxLine) + 2);
  in.getline(&(*text)[0], kMaxLine + 2);
  const std::streamsize got = in.gcount();
  if (got == 0 && in.eof()) return false;
  if (in.fail() && !in.eof()) {  // the buffer filled before the line ended
    in.clear();
    in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    *too_long = true;
    text->clear();
    return true;
  }
  const bool delimited = !in.eof();
  const size_t length = static_cast<size_t>(got - (delimited ? 1 : 0));
  text->resize(length);
  in.clear(in.rdstate() & std::ios::eofbit);
  if (length > static_cast<size_t>(kMaxLine) && (*text)[kMaxLine] != '\r') {
    *too_long = true;
    text->clear();
  }
  return true;
}

bool ParseCommand(const std::string& text, size_t line, Command* out) {
  // A UTF-8 byte order mark, as every text file footfall reads may start with (one saved by a
  // Windows editor): else the first command was "unknown command 'snap'", the mark unseen.
  const bool bom = line == 1 && text.compare(0, 3, "\xEF\xBB\xBF") == 0;
  const std::string whole = bom ? text.substr(3) : text;
  // A carriage return followed by more of the line, comments included: lines ended by CR alone
  // (classic Mac OS) ran together, "snap: expected 3 numbers, found 7", or all went unanswered
  // behind a first comment line (point files refuse them alike).
  if (const size_t cr = whole.find('\r');
      cr != std::string::npos && whole.find_first_not_of(" \t\r\v\f", cr) != std::string::npos) {
    *out = Command{};
    out->line = line;
    out->error =
        "carriage return within the line: lines ended by CR alone (classic Mac OS) are not "
        "read (end lines with LF or CRLF)";
    return true;
  }
  const std::string command = WithoutComment(whole);
  if (command.find_first_not_of(" \t\r\v\f") == std::string::npos) return false;
  *out = Command{};
  out->line = line;
  ParseQueryText(command, &out->query, &out->error);
  return true;
}

// One JSON scalar (a number, a string, a boolean) as nlohmann writes it, bytes that are not
// UTF-8 replaced. Answer lines are built from scalars: a JSON value with children allocates as
// it is destroyed (nlohmann), so memory running out there ended the run with an abort, its
// answers lost; a failure building a line is now an error like any other.
template <typename T>
std::string Scalar(const T& value) {
  return nlohmann::json(value).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string VecText(const Vec3& v) {
  return "[" + Scalar(v.x) + "," + Scalar(v.y) + "," + Scalar(v.z) + "]";
}

std::string ErrorLine(size_t line, const std::string& message) {
  return "{\"op\":\"error\",\"line\":" + Scalar(line) + ",\"message\":" + Scalar(message) + "}";
}

// Runs a block of commands (batching each kind) and prints one line per command, in order.
bool RunBlock(TerrainSession& session, TerrainHandle terrain, double tolerance,
              const std::vector<Command>& block) {
  // Snaps and normals go as their own batches (a server shows each as what it is).
  std::vector<Vec3> snaps, normals;
  std::vector<StepQuery> steps;
  for (const Command& c : block) {
    if (!c.error.empty()) continue;
    if (c.query.op == QueryOp::kNext)
      steps.push_back({c.query.point, c.query.direction});
    else
      (c.query.op == QueryOp::kNormal ? normals : snaps).push_back(c.query.point);
  }
  std::vector<Foothold> snap_answers(snaps.size()), normal_answers(normals.size()),
      step_answers(steps.size());
  const Status snap_status =
      snaps.empty() ? Status::kOk
                    : session.Snap(terrain, snaps.data(), snaps.size(), snap_answers.data());
  const std::string snap_error = session.last_error();
  const Status normal_status =
      normals.empty()
          ? Status::kOk
          : session.Normal(terrain, normals.data(), normals.size(), normal_answers.data());
  const std::string normal_error = session.last_error();
  const Status step_status = steps.empty() ? Status::kOk
                                           : session.Next(terrain, steps.data(), steps.size(),
                                                          tolerance, step_answers.data());
  const std::string step_error = session.last_error();
  bool ok = true;
  size_t snap_at = 0, normal_at = 0, step_at = 0;
  for (const Command& c : block) {
    std::string j;
    if (!c.error.empty()) {
      j = ErrorLine(c.line, c.error);
      ok = false;
    } else {
      const QueryOp op = c.query.op;
      const Status call = op == QueryOp::kNext     ? step_status
                          : op == QueryOp::kNormal ? normal_status
                                                   : snap_status;
      const Foothold& f = op == QueryOp::kNext     ? step_answers[step_at++]
                          : op == QueryOp::kNormal ? normal_answers[normal_at++]
                                                   : snap_answers[snap_at++];
      const std::string op_text = "{\"op\":" + Scalar(QueryOpName(op));
      if (call != Status::kOk) {
        const std::string& why = op == QueryOp::kNext     ? step_error
                                 : op == QueryOp::kNormal ? normal_error
                                                          : snap_error;
        j = ErrorLine(c.line, why);
        ok = false;
      } else if (f.status == Status::kOk) {
        j = op_text + ",\"found\":true,\"index\":" + Scalar(f.index) +
            ",\"point\":" + VecText(f.point) + ",\"normal\":" + VecText(f.normal) + "}";
      } else if (f.status == Status::kNoFoothold) {
        j = op_text + ",\"found\":false}";
      } else {
        const std::string why = f.status != Status::kInvalidArgument
                                    ? StatusName(f.status)
                                    : InvalidQueryReason(c.query.op);
        j = ErrorLine(c.line, std::string(QueryOpName(op)) + ": " + why);
        ok = false;
      }
    }
    std::cout << j << '\n';
  }
  std::cout.flush();
  return ok;
}

struct QueryFlags {
  TerrainFlags terrain;
  double tolerance = 0;
};

int RunQuery(const QueryFlags& flags) {
  std::unique_ptr<TerrainSession> session;
  TerrainHandle terrain = 0;
  std::string error;
  if (OpenTerrain(flags.terrain, &session, &terrain, &error) != Status::kOk) {
    std::cerr << "footfall query: " << error << '\n';
    return 1;
  }
  bool ok = true;
  std::vector<Command> block;
  std::string text;
  size_t line = 0;
  constexpr size_t kBlock = 4096;
  bool too_long = false;
  while (ReadLine(std::cin, &text, &too_long)) {
    ++line;
    Command c;
    if (too_long) {
      c.line = line;
      c.error = "line longer than " + std::to_string(kMaxLine) + " characters";
      block.push_back(std::move(c));
    } else if (ParseCommand(text, line, &c)) {
      block.push_back(std::move(c));
    }
    // Answer at once when no more input is waiting, so interactive callers are never stalled.
    if (block.size() >= kBlock || (!block.empty() && !StandardInputReady())) {
      ok = RunBlock(*session, terrain, flags.tolerance, block) && ok;
      block.clear();
      if (!std::cout) break;  // answers that cannot be written: stop reading
    }
  }
  // A read error ends the input as the end of the file does: say so (stdin a directory, or a
  // terminal gone, answered nothing and exited 0).
  const int read_error = StandardInputError();
  if (!block.empty() && std::cout) ok = RunBlock(*session, terrain, flags.tolerance, block) && ok;
  // (SIGPIPE is ignored: a reader gone, or a full disk, left every answer lost and exit 0.)
  if (!std::cout) {
    const int why = StandardOutputError() ? StandardOutputError() : EIO;
    std::cerr << "footfall query: cannot write the answers to stdout (line " << line
              << " read): " << std::strerror(why) << '\n';
    return 1;
  }
  if (read_error) {
    std::cerr << "footfall query: cannot read stdin after line " << line << ": "
              << std::strerror(read_error) << '\n';
    return 1;
  }
  return ok ? 0 : 1;
}

}  // namespace

void AddQueryCommand(CLI::App& app, int* exit_code) {
  auto flags = std::make_shared<QueryFlags>();
  CLI::App* cmd = app.add_subcommand(
      "query",
      "Answer terrain queries from stdin, one per line: 'snap X Y Z', 'normal X Y Z', "
      "'next X Y Z DX DY DZ'; one JSON object per line on stdout");
  AddTerrainFlags(cmd, &flags->terrain);
  cmd->add_option("--tolerance", flags->tolerance,
                  "next: candidate radius around the ideal point (default, and 0: the step "
                  "length)")
      ->check(FiniteAtLeast(0));
  cmd->callback([flags, exit_code] { *exit_code = RunQuery(*flags); });
}

}  // namespace footfall::cli
