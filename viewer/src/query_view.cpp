#include "footfall/viewer/query_view.h"

#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>

namespace footfall::viewer {
namespace {

bool ParseNumber(const std::string& token, double* value) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, *value);
  return ec == std::errc() && ptr == last && std::isfinite(*value);
}

}  // namespace

bool ParseQuerySpec(const std::string& text, QuerySpec* out, std::string* error) {
  std::string spaced = text;
  for (char& c : spaced) {
    if (c == ',') c = ' ';
  }
  std::istringstream in(spaced);
  std::vector<std::string> tokens;
  for (std::string t; in >> t;) tokens.push_back(t);
  if (tokens.empty()) {
    *error = "empty query (expected 'snap X Y Z', 'normal X Y Z' or 'next X Y Z DX DY DZ')";
    return false;
  }
  QuerySpec spec;
  const std::string& op = tokens[0];
  size_t want = 3;
  const char* names = "X Y Z";
  if (op == "snap") {
    spec.op = QueryOp::kSnap;
  } else if (op == "normal") {
    spec.op = QueryOp::kNormal;
  } else if (op == "next") {
    spec.op = QueryOp::kNext, want = 6, names = "X Y Z DX DY DZ";
  } else {
    *error = "unknown query '" + op +
             "' (expected 'snap X Y Z', 'normal X Y Z' or 'next X Y Z DX DY DZ')";
    return false;
  }
  if (tokens.size() - 1 != want) {
    *error = op + ": expected " + std::to_string(want) + " numbers (" + names + "), found " +
             std::to_string(tokens.size() - 1);
    return false;
  }
  double v[6] = {0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < want; ++i) {
    if (!ParseNumber(tokens[i + 1], &v[i])) {
      *error = op + ": argument " + std::to_string(i + 1) + " '" + tokens[i + 1] +
               "' is not a finite number";
      return false;
    }
  }
  spec.point = {v[0], v[1], v[2]};
  spec.direction = {v[3], v[4], v[5]};
  if (spec.op == QueryOp::kNext && Length2(spec.direction) == 0) {
    *error = "next: direction DX DY DZ must be non-zero";
    return false;
  }
  *out = spec;
  return true;
}

std::string FormatQuerySpec(const QuerySpec& spec) {
  std::ostringstream out;
  out << QueryOpName(spec.op) << ' ' << spec.point.x << ' ' << spec.point.y << ' '
      << spec.point.z;
  if (spec.op == QueryOp::kNext)
    out << ' ' << spec.direction.x << ' ' << spec.direction.y << ' ' << spec.direction.z;
  return out.str();
}

QueryView RunQuery(const TerrainGrid& grid, const QuerySpec& spec) {
  QueryView view;
  view.spec = spec;
  view.traced = true;
  if (spec.op == QueryOp::kNext) {
    view.result = grid.Next({spec.point, spec.direction}, spec.tolerance, &view.trace);
  } else {
    view.result = grid.Snap(spec.point, &view.trace);
  }
  return view;
}

QueryView FromRecent(const RecentQuery& query, const TerrainGrid* grid) {
  QuerySpec spec;
  spec.op = query.op;
  spec.point = query.point;
  spec.direction = query.direction;
  spec.tolerance = query.tolerance;
  QueryView view;
  if (grid && !grid->empty()) view = RunQuery(*grid, spec);
  view.spec = spec;
  view.result = query.result;
  view.live = true;
  view.sequence = query.sequence;
  if (!view.traced) {
    view.trace.ideal = spec.op == QueryOp::kNext ? spec.point + spec.direction : spec.point;
  }
  return view;
}

}  // namespace footfall::viewer
