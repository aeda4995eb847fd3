// ParseQueryText / FormatQueryText: the query line syntax shared by `footfall query` and
// `footfall-view --query`.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <utility>

#include "footfall/client/query_text.h"

namespace footfall {
namespace {

TEST_CASE("query lines parse into an op, a point and a direction", "[client][query_text]") {
  QueryText q;
  std::string error;
  SECTION("snap and normal take a point") {
    REQUIRE(ParseQueryText("snap 1.5 -2 3e1", &q, &error));
    CHECK(q.op == QueryOp::kSnap);
    CHECK(q.point == Vec3{1.5, -2, 30});
    REQUIRE(ParseQueryText("\t normal +1 2 3 \r", &q, &error));
    CHECK(q.op == QueryOp::kNormal);
    CHECK(q.point == Vec3{1, 2, 3});
  }
  SECTION("next takes a foot and a step") {
    REQUIRE(ParseQueryText("next 1 2 3 0.5 0 -0.5", &q, &error));
    CHECK(q.op == QueryOp::kNext);
    CHECK(q.point == Vec3{1, 2, 3});
    CHECK(q.direction == Vec3{0.5, 0, -0.5});
    // A direction too small to square is not zero (the engine answers it).
    REQUIRE(ParseQueryText("next 1 2 3 1e-200 0 0", &q, &error));
    CHECK(q.direction == Vec3{1e-200, 0, 0});
  }
  SECTION("commas separate numbers like spaces") {
    REQUIRE(ParseQueryText("next 1,2,3 0.5,0,-0.5", &q, &error));
    CHECK(q.point == Vec3{1, 2, 3});
    CHECK(q.direction == Vec3{0.5, 0, -0.5});
    REQUIRE(ParseQueryText("snap 4, 5 ,6", &q, &error));
    CHECK(q.point == Vec3{4, 5, 6});
  }
  SECTION("formatting gives text that parses back to the same query") {
    REQUIRE(ParseQueryText("next 1 2 3 0.5,0,-0.5", &q, &error));
    CHECK(FormatQueryText(q) == "next 1 2 3 0.5 0 -0.5");
    QueryText back;
    REQUIRE(ParseQueryText(FormatQueryText(q), &back, &error));
    CHECK(back.point == q.point);
    CHECK(back.direction == q.direction);
    q.op = QueryOp::kNormal;
    CHECK(FormatQueryText(q) == "normal 1 2 3");
    // Every digit that tells two queries apart (6 significant digits wrote both "snap 10 1 10").
    for (const char* text :
         {"snap 10.00001 1 10", "snap 10.00004 1 10", "snap 123456.7 -0.1 1e-300",
          "next 500010.3 1 5000010.2 0.1 0 -2.5e-07"}) {
      REQUIRE(ParseQueryText(text, &q, &error));
      CHECK(FormatQueryText(q) == text);
    }
  }
}

TEST_CASE("malformed query lines say what was expected", "[client][query_text]") {
  const std::string kZero = "next: direction DX DY DZ must be non-zero";
  const std::string kNoneBefore =
      "a comma with no number before it (expected numbers separated by spaces or single commas)";
  const std::pair<std::string, std::string> bad[] = {
      {"", "empty query (expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ)"},
      {" , ", kNoneBefore},
      // A comma with no number on one side dropped a number ("0,,0" read as "0 0").
      {"snap 0,,0 0", kNoneBefore},
      {"snap 0, ,0 0", kNoneBefore},
      {",snap 0 0 0", kNoneBefore},
      // A comma after the command word has no number before it either (it was taken).
      {"snap ,1,2,3", kNoneBefore},
      {"snap,1,2,3", kNoneBefore},
      {"next ,0,0,0,1,0,0", kNoneBefore},
      {"snap 0 0 0,",
       "a comma with no number after it (expected numbers separated by spaces or "
       "single commas)"},
      // Microsoft C's infinity is a number that is not finite, not "1." and a comment.
      {WithoutComment("snap 1.#INF 0 0"),
       "snap: argument 1 '1.#INF' is not a finite number (Microsoft C's NaN or infinity)"},
      {"jump 1 2 3",
       "unknown command 'jump' (expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ)"},
      {"SNAP 1 2 3",
       "unknown command 'SNAP' (expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ)"},
      {"normal 4 4", "normal: expected 3 numbers, found 2"},
      {"snap 1 2 3 4", "snap: expected 3 numbers, found 4"},
      {"next 1 2 3", "next: expected 6 numbers, found 3"},
      {"snap 1 x 1", "snap: argument 2 'x' is not a finite number"},
      {"snap 1 nan 3", "snap: argument 2 'nan' is not a finite number"},
      {"normal 1 2 inf", "normal: argument 3 'inf' is not a finite number"},
      {"snap 1 2 1e999", "snap: argument 3 '1e999' is not a finite number"},
      {"snap 1 2 3x", "snap: argument 3 '3x' is not a finite number"},
      {"snap 1 2 ++3", "snap: argument 3 '++3' is not a finite number"},
      {"snap +-1 2 3", "snap: argument 1 '+-1' is not a finite number"},
      {"next 1 2 3 0 0 0", kZero},
      {"next 1 2 3 0,-0,0", kZero},
      // Bad text is shown short and without control bytes (a 1 MB token was echoed whole).
      {"snap 1 2 " + std::string(100000, '7') + "x",
       "snap: argument 3 '77777777777777777777777777777777... (100001 bytes)' is not a finite "
       "number"},
      // ... with the bytes a '?' stands for (or that do not show, a byte-order mark).
      {std::string("snap 1 a\x01 3"), "snap: argument 2 'a?' (bytes 61 01) is not a finite number"},
      {std::string("snap 1 2 3\x7f"), "snap: argument 3 '3?' (bytes 33 7F) is not a finite number"},
      {"\xef\xbb\xbfsnap 1 2 3",
       "unknown command '\xef\xbb\xbfsnap' (bytes EF BB BF 73 6E 61 70) (expected snap X Y Z, "
       "normal X Y Z or next X Y Z DX DY DZ)"},
  };
  for (const auto& [text, message] : bad) {
    INFO("'" << text << "'");
    QueryText q;
    q.point = {7, 8, 9};
    std::string error;
    CHECK_FALSE(ParseQueryText(text, &q, &error));
    CHECK(error == message);
    CHECK(q.point == Vec3{7, 8, 9});  // left alone
  }
}

TEST_CASE("number tokens are whole finite decimals", "[client][query_text]") {
  double v = 7;
  CHECK(ParseFiniteNumber("-2.5e-1", &v));
  CHECK(v == -0.25);
  CHECK(ParseFiniteNumber("+3", &v));
  CHECK(v == 3);
  // Too small for a double: zero of its sign, as in terrain files (it was "not a finite number").
  CHECK(ParseFiniteNumber("-1e-400", &v));
  CHECK(v == 0);
  CHECK(std::signbit(v));
  for (const char* bad :
       {"", "+", "x", "3x", " 3", "++3", "+-3", "nan", "inf", "-inf", "1e999", "0x10"}) {
    INFO("'" << bad << "'");
    v = 7;
    CHECK_FALSE(ParseFiniteNumber(bad, &v));
    CHECK(v == 7);  // left alone
  }
}

TEST_CASE("query ops have stable names", "[client][query_text]") {
  CHECK(std::string(QueryOpName(QueryOp::kSnap)) == "snap");
  CHECK(std::string(QueryOpName(QueryOp::kNormal)) == "normal");
  CHECK(std::string(QueryOpName(QueryOp::kNext)) == "next");
}

}  // namespace
}  // namespace footfall
