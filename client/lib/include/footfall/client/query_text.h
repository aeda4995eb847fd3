// Terrain queries as one line of text, the syntax of `footfall query` (stdin) and
// `footfall-view --query`: "snap X Y Z", "normal X Y Z" or "next X Y Z DX DY DZ", the numbers
// separated by spaces, tabs or commas ("next 1 2 3 0.5,0,-0.5").
#pragma once

#include <string>

#include "footfall/terrain/vec3.h"

namespace footfall {

enum class QueryOp { kSnap, kNormal, kNext };

// A short stable name: "snap", "normal", "next".
const char* QueryOpName(QueryOp op);

// One query as written.
struct QueryText {
  QueryOp op = QueryOp::kSnap;
  Vec3 point;      // world space: the query point, or the foot for next
  Vec3 direction;  // world space, next only: non-zero, its length is the step length
};

// Parses one whole token as a finite decimal number ("1.5", "-2", "+3e1"): false for anything
// else, including "nan", "inf", values beyond a double's range, a second sign ("+-1") and
// trailing characters. A value too small for a double ("1e-400") reads as zero, as in terrain
// files.
bool ParseFiniteNumber(const std::string& token, double* value);

// `line` without its comment: the text before its first '#' (but the one of Microsoft C's
// "1.#INF", which is a number that is not finite, not a comment).
std::string WithoutComment(const std::string& line);

// Parses one query line (no comments: callers strip them, WithoutComment). Numbers are finite
// decimals, with an optional leading '+'. On failure returns false, leaves *out alone and sets
// *error to one line saying what was expected, e.g. "normal: expected 3 numbers, found 2", "snap:
// argument 2 'x' is not a finite number", "next: direction DX DY DZ must be non-zero", "unknown
// command 'jump' (expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ)".
bool ParseQueryText(const std::string& text, QueryText* out, std::string* error);

// Why the engine answers a query of `op` kInvalidArgument, as `footfall query` and
// `footfall-view --query` report it: "invalid query (a coordinate more than 1e15 from the
// terrain's centre)", or for next a zero direction or one too long to square too.
std::string InvalidQueryReason(QueryOp op);

// "next 1 0 2 0.5 0 0": the query in the syntax ParseQueryText reads, each number in the
// shortest form that reads back as the same double (to 6 significant digits, 10.00001 and
// 10.00004 were both written "10").
std::string FormatQueryText(const QueryText& query);

}  // namespace footfall
