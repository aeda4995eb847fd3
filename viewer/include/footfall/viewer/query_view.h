// Queries the viewer draws: parsed from --query strings or received from a live footfalld, and
// answered (or re-traced) by an in-process TerrainGrid so the examined cells and candidate
// samples can be shown.
#pragma once

#include <cstdint>
#include <string>

#include "footfall/client/recent_queries.h"
#include "footfall/terrain/grid.h"

namespace footfall::viewer {

// One query as the user wrote it: "snap X Y Z", "normal X Y Z" or "next X Y Z DX DY DZ".
struct QuerySpec {
  QueryOp op = QueryOp::kSnap;
  Vec3 point;      // world space: the query point, or the foot for next
  Vec3 direction;  // world space, next only; non-zero, its length is the step length
  double tolerance = 0;  // [Units: wu] next only; <= 0 means one step length
};

// Parses `text` (numbers separated by spaces or commas). On failure returns false and sets
// *error to what was expected, e.g. "next: expected 6 numbers (X Y Z DX DY DZ), found 4".
bool ParseQuerySpec(const std::string& text, QuerySpec* out, std::string* error);

// "next 1 0 2 0.5 0 0": a query in the syntax ParseQuerySpec reads.
std::string FormatQuerySpec(const QuerySpec& spec);

// A query with its answer and, when a grid was at hand, what the grid examined.
struct QueryView {
  QuerySpec spec;
  Foothold result;        // the answer drawn as the chosen sample
  QueryTrace trace;       // valid when `traced`
  bool traced = false;
  bool live = false;      // received from footfalld rather than given on the command line
  uint64_t sequence = 0;  // live: the server's query sequence
};

// Answers `spec` with `grid`, recording its trace.
QueryView RunQuery(const TerrainGrid& grid, const QuerySpec& spec);

// A query footfalld answered. Its result is the server's; when `grid` is given (the same
// terrain loaded locally) the query is traced again on it to show cells and candidates.
QueryView FromRecent(const RecentQuery& query, const TerrainGrid* grid);

}  // namespace footfall::viewer
