// Queries the viewer draws: parsed from --query strings or received from a live footfalld, and
// answered (or re-traced) by an in-process TerrainGrid so the examined cells and candidate
// samples can be shown.
#pragma once

#include <cstdint>
#include <string>

#include "footfall/client/query_text.h"
#include "footfall/client/recent_queries.h"
#include "footfall/terrain/grid.h"

namespace footfall::viewer {

// One query to draw: as the user wrote it (ParseQueryText, query_text.h) or as footfalld
// received it, with the candidate radius it is answered with.
struct QuerySpec : QueryText {
  double tolerance = 0;  // [Units: wu] next only; <= 0 means one step length
};

// A query with its answer and, when a grid was at hand, what the grid examined.
struct QueryView {
  QuerySpec spec;
  Foothold result;   // the answer drawn as the chosen sample
  QueryTrace trace;  // valid when `traced`
  bool traced = false;
  bool live = false;      // received from footfalld rather than given on the command line
  uint64_t sequence = 0;  // live: the server's query sequence
  // live: the local terrain answers it otherwise than footfalld did (the query was on another
  // terrain): drawn with the server's answer alone, untraced.
  bool other_terrain = false;
};

// Answers `spec` with `grid`, recording its trace.
QueryView RunQuery(const TerrainGrid& grid, const QuerySpec& spec);

// A query footfalld answered. Its result is the server's; when `grid` is given (the same
// terrain loaded locally) the query is traced again on it to show cells and candidates,
// unless the grid's answer differs from the server's (`other_terrain`).
QueryView FromRecent(const RecentQuery& query, const TerrainGrid* grid);

}  // namespace footfall::viewer
