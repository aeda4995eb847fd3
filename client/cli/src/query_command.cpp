// `footfall query`: answers snap / normal / next commands read from stdin, one JSON line each.
#include <poll.h>
#include <unistd.h>

#include <charconv>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "terrain_flags.h"

namespace footfall::cli {
namespace {

enum class Op { kSnap, kNormal, kNext };

struct Command {
  size_t line = 0;
  Op op = Op::kSnap;
  Vec3 a, b;
  std::string error;  // non-empty: the line was malformed
};

const char* OpName(Op op) {
  return op == Op::kSnap ? "snap" : op == Op::kNormal ? "normal" : "next";
}

bool ParseNumber(const std::string& token, double* value) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, *value);
  return ec == std::errc() && ptr == last && std::isfinite(*value);
}

// Parses one command line; returns false for blank and comment lines.
bool ParseCommand(const std::string& text, size_t line, Command* out) {
  std::istringstream in(text.substr(0, text.find('#')));
  std::vector<std::string> tokens;
  for (std::string t; in >> t;) tokens.push_back(t);
  if (tokens.empty()) return false;
  *out = Command{};
  out->line = line;
  const std::string& op = tokens[0];
  size_t want;
  if (op == "snap") {
    out->op = Op::kSnap, want = 3;
  } else if (op == "normal") {
    out->op = Op::kNormal, want = 3;
  } else if (op == "next") {
    out->op = Op::kNext, want = 6;
  } else {
    out->error = "unknown command '" + op + "' (expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ)";
    return true;
  }
  if (tokens.size() - 1 != want) {
    out->error = op + ": expected " + std::to_string(want) + " numbers, found " +
                 std::to_string(tokens.size() - 1);
    return true;
  }
  double v[6];
  for (size_t i = 0; i < want; ++i) {
    if (!ParseNumber(tokens[i + 1], &v[i])) {
      out->error = op + ": argument " + std::to_string(i + 1) + " '" + tokens[i + 1] +
                   "' is not a finite number";
      return true;
    }
  }
  out->a = {v[0], v[1], v[2]};
  if (want == 6) {
    out->b = {v[3], v[4], v[5]};
    if (Length2(out->b) == 0) out->error = "next: direction DX DY DZ must be non-zero";
  }
  return true;
}

nlohmann::ordered_json Vec(const Vec3& v) { return nlohmann::ordered_json::array({v.x, v.y, v.z}); }

bool InputReady() {
  pollfd p{STDIN_FILENO, POLLIN, 0};
  return poll(&p, 1, 0) > 0;
}

// Runs a block of commands (batching each kind) and prints one line per command, in order.
bool RunBlock(TerrainSession& session, TerrainHandle terrain, double tolerance,
              const std::vector<Command>& block) {
  std::vector<Vec3> points;
  std::vector<StepQuery> steps;
  for (const Command& c : block) {
    if (!c.error.empty()) continue;
    if (c.op == Op::kNext) steps.push_back({c.a, c.b});
    else points.push_back(c.a);
  }
  std::vector<Foothold> point_answers(points.size()), step_answers(steps.size());
  Status ps = points.empty() ? Status::kOk
                             : session.Snap(terrain, points.data(), points.size(),
                                            point_answers.data());
  std::string perr = session.last_error();
  Status ss = steps.empty() ? Status::kOk
                            : session.Next(terrain, steps.data(), steps.size(), tolerance,
                                           step_answers.data());
  std::string serr = session.last_error();
  bool ok = true;
  size_t pi = 0, si = 0;
  for (const Command& c : block) {
    nlohmann::ordered_json j;
    if (!c.error.empty()) {
      j = {{"op", "error"}, {"line", c.line}, {"message", c.error}};
      ok = false;
    } else {
      const bool next = c.op == Op::kNext;
      const Status call = next ? ss : ps;
      const Foothold& f = next ? step_answers[si++] : point_answers[pi++];
      if (call != Status::kOk) {
        j = {{"op", "error"}, {"line", c.line}, {"message", next ? serr : perr}};
        ok = false;
      } else if (f.status == Status::kOk) {
        j = {{"op", OpName(c.op)}, {"found", true}, {"index", f.index}, {"point", Vec(f.point)},
             {"normal", Vec(f.normal)}};
      } else if (f.status == Status::kNoFoothold) {
        j = {{"op", OpName(c.op)}, {"found", false}};
      } else {
        j = {{"op", "error"}, {"line", c.line},
             {"message", std::string(OpName(c.op)) + ": " + StatusName(f.status)}};
        ok = false;
      }
    }
    std::cout << j.dump() << '\n';
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
  while (std::getline(std::cin, text)) {
    ++line;
    Command c;
    if (ParseCommand(text, line, &c)) block.push_back(std::move(c));
    // Answer at once when no more input is waiting, so interactive callers are never stalled.
    if (block.size() >= kBlock || (!block.empty() && !InputReady())) {
      ok = RunBlock(*session, terrain, flags.tolerance, block) && ok;
      block.clear();
    }
  }
  if (!block.empty()) ok = RunBlock(*session, terrain, flags.tolerance, block) && ok;
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
                  "next: candidate radius around the ideal point (default: the step length)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([flags, exit_code] { *exit_code = RunQuery(*flags); });
}

}  // namespace footfall::cli
