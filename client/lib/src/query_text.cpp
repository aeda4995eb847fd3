#include "footfall/client/query_text.h"

#include <cctype>
#include <charconv>
#include <sstream>
#include <vector>

#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/shown_text.h"

namespace footfall {
namespace {

constexpr const char* kForms = "snap X Y Z, normal X Y Z or next X Y Z DX DY DZ";

}  // namespace

bool ParseFiniteNumber(const std::string& token, double* value) {
  // The terrain files' reader: one sign at most ("+-1" is no number), tiny values as zero.
  return ParseFiniteDecimal(token, value);
}

std::string InvalidQueryReason(QueryOp op) {
  // (It said "farther than 1e15 from the terrain" of a point 7e14 from its nearest sample, and
  // "a direction too small", which is never refused: the range is per axis, from the grid's
  // centre.)
  return op == QueryOp::kNext
             ? "invalid query (a zero direction, one too long to square, or a foot or ideal point "
               "with a coordinate more than 1e15 from the terrain's centre)"
             : "invalid query (a coordinate more than 1e15 from the terrain's centre)";
}

const char* QueryOpName(QueryOp op) {
  switch (op) {
    case QueryOp::kSnap:
      return "snap";
    case QueryOp::kNormal:
      return "normal";
    case QueryOp::kNext:
      return "next";
  }
  return "unknown";
}

std::string WithoutComment(const std::string& line) { return line.substr(0, CommentStart(line)); }

bool ParseQueryText(const std::string& text, QueryText* out, std::string* error) {
  // Words are separated by white space, numbers also by commas ("next 1,0,2 0, 0, 1"); a comma
  // with no number on one side (",,", a comma first, right after the command, or last) is
  // refused: ",," read as one comma dropped a number.
  std::vector<std::string> tokens;
  bool comma_pending = false;
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == ',') {
      // The first word is the command: a comma after it has no number before it either.
      if (tokens.size() <= 1 || comma_pending) {
        *error =
            "a comma with no number before it (expected numbers separated by spaces or "
            "single commas)";
        return false;
      }
      comma_pending = true, ++i;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else {
      const size_t end = text.find_first_of(", \t\r\n\f\v", i);
      tokens.push_back(text.substr(i, end == std::string::npos ? end : end - i));
      comma_pending = false;
      i = end == std::string::npos ? text.size() : end;
    }
  }
  if (comma_pending) {
    *error =
        "a comma with no number after it (expected numbers separated by spaces or single "
        "commas)";
    return false;
  }
  if (tokens.empty()) {
    *error = std::string("empty query (expected ") + kForms + ")";
    return false;
  }
  QueryText query;
  const std::string& op = tokens[0];
  size_t want = 3;
  if (op == "snap") {
    query.op = QueryOp::kSnap;
  } else if (op == "normal") {
    query.op = QueryOp::kNormal;
  } else if (op == "next") {
    query.op = QueryOp::kNext, want = 6;
  } else {
    *error = "unknown command '" + ShownText(op) + "'" + HiddenBytesNote(op) + " (expected " +
             kForms + ")";
    return false;
  }
  if (tokens.size() - 1 != want) {
    *error = op + ": expected " + std::to_string(want) + " numbers, found " +
             std::to_string(tokens.size() - 1);
    return false;
  }
  double v[6] = {0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < want; ++i) {
    if (!ParseFiniteNumber(tokens[i + 1], &v[i])) {
      *error = op + ": argument " + std::to_string(i + 1) + " '" + ShownText(tokens[i + 1]) + "'" +
               HiddenBytesNote(tokens[i + 1]) + " is not a finite number" +
               NotFiniteNote(tokens[i + 1]);
      return false;
    }
  }
  query.point = {v[0], v[1], v[2]};
  query.direction = {v[3], v[4], v[5]};
  if (query.op == QueryOp::kNext && query.direction.x == 0 && query.direction.y == 0 &&
      query.direction.z == 0) {
    *error = "next: direction DX DY DZ must be non-zero";
    return false;
  }
  *out = query;
  return true;
}

std::string FormatQueryText(const QueryText& query) {
  std::string out = QueryOpName(query.op);
  auto put = [&out](double v) {
    char digits[32];
    const auto written = std::to_chars(digits, digits + sizeof digits, v);
    out += ' ';
    out.append(digits, written.ptr);
  };
  put(query.point.x), put(query.point.y), put(query.point.z);
  if (query.op == QueryOp::kNext)
    put(query.direction.x), put(query.direction.y), put(query.direction.z);
  return out;
}

}  // namespace footfall
