// The point file reader: valid files load with normalised normals; each kind of bad line gives
// an error naming file, line and what was expected.
#include <unistd.h>
#include <cmath>

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/point_file.h"

#include "footfall/terrain/input_file.h"

using namespace footfall;

namespace {
// `ascii` as UTF-16 (width 2) or UTF-32 (width 4) text, little- or big-endian, with or without
// a byte order mark.
std::string Wide(const std::string& ascii, int width, bool little, bool mark) {
  std::string out;
  auto put = [&](uint32_t c) {
    for (int b = 0; b < width; ++b)
      out += static_cast<char>((c >> (8 * (little ? b : width - 1 - b))) & 0xff);
  };
  if (mark) put(0xFEFF);
  for (const char c : ascii) put(static_cast<unsigned char>(c));
  return out;
}

Status Read(const std::string& text, RawSamples* out, std::string* error) {
  std::istringstream in(text);
  return ReadPointStream(in, "t.pts", out, error);
}
}  // namespace

TEST_CASE("ReadPointStream reads samples", "[terrain][point_file]") {
  RawSamples s;
  std::string error;
  const std::string text =
      "# a comment\r\n"
      "\r\n"
      "0 1 2 0 2 0   # trailing comment\r\n"
      "\t+1.5e0  -2 3e-1 3 0 4\n"
      "   \n"
      "7 8 9 0 0 -1";
  REQUIRE(Read(text, &s, &error) == Status::kOk);
  REQUIRE(s.size() == 3);
  CHECK(s.points[0] == Vec3{0, 1, 2});
  CHECK(s.normals[0] == Vec3{0, 1, 0});
  CHECK(s.points[1] == Vec3{1.5, -2, 0.3});
  CHECK(s.normals[1].x == Approx(0.6));
  CHECK(s.normals[1].z == Approx(0.8));
  CHECK(s.points[2] == Vec3{7, 8, 9});
}

TEST_CASE("ReadPointStream accepts a UTF-8 byte order mark and bare decimal points",
          "[terrain][point_file]") {
  RawSamples s;
  std::string error;
  REQUIRE(Read("\xEF\xBB\xBF.5 5. 1E1 0 1 0\r\n-0 +2 3e-2\t0 0 1\n", &s, &error) == Status::kOk);
  REQUIRE(s.size() == 2);
  CHECK(s.points[0] == Vec3{0.5, 5, 10});
  CHECK(s.points[1] == Vec3{0, 2, 0.03});
}

TEST_CASE("ReadPointStream reads numbers too small for a double as zero", "[terrain][point_file]") {
  // 1e-400 was refused as out of range, though OBJ and height maps read it as 0.
  RawSamples s;
  std::string error;
  const std::string tiny = "0." + std::string(400, '0') + "1";
  REQUIRE(Read("1e-400 -1e-400 " + tiny + " 0 1 0\n", &s, &error) == Status::kOk);
  REQUIRE(s.size() == 1);
  CHECK(s.points[0].x == 0);
  CHECK(std::signbit(s.points[0].y));
  CHECK(s.points[0].z == 0);
  CHECK(Read("1e400 0 0 0 1 0\n", &s, &error) == Status::kParseError);
  CHECK_THAT(error, Catch::Contains("t.pts:1: column 1: '1e400' is out of range"));
}

TEST_CASE("ReadPointStream rejects bad lines with file and line", "[terrain][point_file]") {
  RawSamples s;
  std::string error;
  SECTION("wrong count") {
    CHECK(Read("0 0 0 0 1 0\n1 2 3 4 5\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:2: expected 6 numbers (x y z nx ny nz), found 5");
    CHECK(Read("1 2 3 4 5 6 7\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:1: expected 6 numbers (x y z nx ny nz), found 7");
  }
  SECTION("not a number") {
    CHECK(Read("\n\n0 0 abc 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:3: column 3: 'abc' is not a number (expected x y z nx ny nz)");
    CHECK(Read("0 0 1.5x 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error.find("t.pts:1: column 3") == 0);
    // Bytes that do not show are shown as bytes too: a NUL is no question mark.
    CHECK(Read(std::string("0 0 a\0b 0 1 0\n", 14), &s, &error) == Status::kParseError);
    CHECK(error ==
          "t.pts:1: column 3: 'a?b' (bytes 61 00 62) is not a number (expected x y z nx "
          "ny nz)");
    // A decimal comma (a European locale's export) or values separated by commas are named.
    CHECK(Read("0 -0,25 1 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error ==
          "t.pts:1: column 2: '-0,25' is not a number (a decimal comma: write a decimal point, "
          "as in 1.5) (expected x y z nx ny nz)");
    CHECK(Read("0,1,2,0,1,0\n", &s, &error) == Status::kParseError);
    CHECK(error ==
          "t.pts:1: column 1: '0,1,2,0,1,0' is not a number (values are separated by "
          "spaces or tabs, not commas) (expected x y z nx ny nz)");
    // Control characters from the file reach no terminal: ESC and the C1 CSI (U+009B) as '?';
    // other UTF-8 stays.
    CHECK(Read("0 0 \x1b[31mA\xc2\x9b"
               "31m\xc3\xa9 0 1 0\n",
               &s, &error) == Status::kParseError);
    CHECK(error ==
          "t.pts:1: column 3: '?[31mA?31m\xc3\xa9' is not a number (expected x y z nx ny nz)");
  }
  SECTION("NaN or infinite") {
    CHECK(Read("0 0 0 0 1 0\nnan 0 0 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:2: column 1: 'nan' is NaN or infinite (expected a finite number)");
    CHECK(Read("0 inf 0 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error.find("t.pts:1: column 2: 'inf' is NaN or infinite") == 0);
    CHECK(Read("0 1e999 0 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error.find("t.pts:1: column 2: '1e999' is out of range") == 0);
    // Microsoft C's spellings: the '#' starts no comment (the normal 0 0 1 was read).
    CHECK(Read("0 0 1 0 0 1.#INF\n", &s, &error) == Status::kParseError);
    CHECK(error ==
          "t.pts:1: column 6: '1.#INF' is NaN or infinite (Microsoft C's NaN or infinity) "
          "(expected a finite number)");
    CHECK(Read("-1.#IND 0 0 0 1 0 # a comment\n", &s, &error) == Status::kParseError);
    CHECK(error.find("t.pts:1: column 1: '-1.#IND' is NaN or infinite (Microsoft") == 0);
    CHECK(Read("1 2 3 0 1 0 #1.#QNAN\n", &s, &error) == Status::kOk);
    CHECK(s.size() == 1);
    s.clear();
    // Printed at a low precision the words are rounded: "1.#J" was read as "1." and a comment.
    for (const std::string token : {"1.#J", "-1.#J", "1.#R", "1.#IO", "1.#QO", "1.#I", "1.#"}) {
      INFO(token);
      CHECK(Read("0 0 0 0 0 " + token + "\n", &s, &error) == Status::kParseError);
      CHECK(error == "t.pts:1: column 6: '" + token +
                         "' is NaN or infinite (Microsoft C's NaN or infinity) (expected a finite "
                         "number)");
    }
    CHECK(IsMicrosoftNaN("-1.#IND00"));
    CHECK(IsMicrosoftNaN("1.#QNAN"));
    CHECK_FALSE(IsMicrosoftNaN("1.#INF"));
    CHECK_FALSE(IsMicrosoftNaN("1.#J"));
    // A comment right after a whole number is still one.
    CHECK(Read("1 2 3 0 1 0#1.#QNAN\n", &s, &error) == Status::kOk);
    s.clear();
  }
  SECTION("beyond the grid's range") {
    // The grid stores float offsets from its origin and answers within 1e15 of it: coordinates
    // beyond terrain::kMaxCoordinate would answer garbage or infinities.
    CHECK(Read("0 0 0 0 1 0\n1e308 0 0 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:2: column 1: 1e308 is out of range (expected |x| <= 5e+14)");
    CHECK(Read("0 0 -1e39 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:1: column 3: -1e39 is out of range (expected |z| <= 5e+14)");
    CHECK(terrain::kMaxCoordinate == 5e14);
    std::string text = "0 -5e14 0 0 1 0\n";
    REQUIRE(Read(text, &s, &error) == Status::kOk);  // the limit itself is accepted
    // Normals are directions: any finite size is fine.
    REQUIRE(Read("0 0 0 0 1e300 0\n", &s, &error) == Status::kOk);
    s.clear();
  }
  SECTION("zero normal") {
    CHECK(Read("0 0 0 0 0 0\n", &s, &error) == Status::kParseError);
    CHECK(error == "t.pts:1: normal has zero length (expected a non-zero nx ny nz)");
  }
  SECTION("lines ended by CR alone") {
    // Classic Mac OS line ends: CR was read as a space, so the samples after a comment on the
    // first line were dropped without a word (one sample of three, exit 0).
    CHECK(Read("0 0 0 0 1 0 # first\r1 0 0 0 1 0\r2 0 0 0 1 0\r", &s, &error) ==
          Status::kParseError);
    CHECK(error ==
          "t.pts:1: line ends in CR alone (classic Mac OS): convert line ends to LF or "
          "CR LF");
    // A whole file of them is one line longer than 1 MiB: named for its CRs, not its length.
    std::string mac;
    for (int i = 0; i < 100000; ++i) mac += "0 0 0 0 1 0\r";
    CHECK(Read(mac, &s, &error) == Status::kParseError);
    CHECK(error ==
          "t.pts:1: line ends in CR alone (classic Mac OS): convert line ends to LF or "
          "CR LF");
    CHECK(Read("0 0 0 0 1 0\n0 0 0 0 1 0\r1 0 0 0 1 0\n", &s, &error) == Status::kParseError);
    CHECK(error.find("t.pts:2: line ends in CR alone") == 0);
    // CR LF, and a CR at the very end of the file, are line ends.
    REQUIRE(Read("0 0 0 0 1 0\r\n1 0 0 0 1 0\r\r\n2 0 0 0 1 0\r", &s, &error) == Status::kOk);
    CHECK(s.size() == 3);
    s.clear();
  }
  SECTION("UTF-16 and UTF-32 text") {
    // UTF-16 with its mark was "column 1: '\xff\xfe0?' is not a number", UTF-32 was called
    // UTF-16 (its mark starts as UTF-16's), and either without a mark "'0?' is not a number".
    // A short first line too (the first line is all the reader looks at).
    for (const char* ascii : {"0 0 0 0 1 0\n1 0 0 0 1 0\n", "0 0\n1 1\n"}) {
      for (const int width : {2, 4}) {
        for (const bool little : {true, false}) {
          for (const bool mark : {true, false}) {
            INFO(ascii << " width " << width << (little ? " LE" : " BE") << (mark ? " BOM" : ""));
            CHECK(Read(Wide(ascii, width, little, mark), &s, &error) == Status::kParseError);
            CHECK(error == std::string("t.pts:1: UTF-") + (width == 2 ? "16" : "32") +
                               " text (expected ASCII or UTF-8: save the file as UTF-8)");
          }
        }
      }
    }
  }
  SECTION("text that is not UTF-16 or UTF-32 is not called so") {
    CHECK(WideTextProblem("0 0 0 0 1 0\n").empty());
    CHECK(WideTextProblem("\xEF\xBB\xBF"
                          "0 0 0 0 1 0\n")
              .empty());  // UTF-8 with its mark
    CHECK(WideTextProblem("\xC3\xA9t\xC3\xA9").empty());
    CHECK(WideTextProblem(std::string("\x01\0\x02\0", 4)).empty());  // binary
    CHECK(WideTextProblem(std::string("0\0", 2)).empty());           // too short to tell
  }
  SECTION("a line longer than 1 MiB") {
    // A file of NUL bytes, or without line breaks, was read whole into one line (2 to 5 times
    // its size in memory, "out of memory" or "read error" for large ones).
    CHECK(Read("0 0 0 0 1 0\n" + std::string(kMaxLineBytes + 1, '\0') + "\n", &s, &error) ==
          Status::kParseError);
    CHECK(error == "t.pts:2: line longer than 1 MiB (expected x y z nx ny nz)");
    // A line of exactly the limit is read (and judged on its numbers).
    CHECK(Read("0 0 0 0 1 0" + std::string(kMaxLineBytes - 11, ' ') + "\n1 1 1 0 1 0", &s,
               &error) == Status::kOk);
    CHECK(s.size() == 2);
    s.clear();
  }
  CHECK(s.size() == 0);
}

TEST_CASE("ReadPointFile reports a missing file", "[terrain][point_file]") {
  RawSamples s;
  std::string error;
  CHECK(ReadPointFile("/nonexistent/terrain.pts", &s, &error) == Status::kIoError);
  CHECK(error == "/nonexistent/terrain.pts: cannot open file: No such file or directory");
  // An empty path was named by nothing: ": cannot open file: No such file or directory".
  CHECK(ReadPointFile("", &s, &error) == Status::kInvalidArgument);
  CHECK(error == "cannot open file: expected a path, got an empty one");
}

TEST_CASE("ReadPointFile refuses a FIFO or a device at once", "[terrain][point_file]") {
  RawSamples s;
  std::string error;
  // Reading /dev/zero never ends; opening a FIFO waits for a writer.
  CHECK(ReadPointFile("/dev/zero", &s, &error) == Status::kInvalidArgument);
  CHECK(error == "/dev/zero: cannot open file: a device, not a regular file");
  CHECK(ReadPointFile("/tmp", &s, &error) == Status::kInvalidArgument);
  CHECK(error == "/tmp: cannot open file: a directory");
}

TEST_CASE("WritePointFile writes every sample exactly", "[terrain][point_file]") {
  // 12 significant digits moved samples 1e10 from the origin by up to 0.05: a converted point
  // file answered snaps with other samples than the original.
  RawSamples s;
  s.push_back({1e10 + 0.102, -0.0, 1.0 / 3}, Normalize(Vec3{0.1, 1, 0.3}));
  s.push_back({-4.99999999999e14, 5e-324, 123456.789012345678}, {0, 1, 0});
  s.push_back({0.1 + 0.2, 1e-300, -2.5}, Normalize(Vec3{1, 1, 1}));
  // Unit normals read back as written: normalised again, two in three moved by a bit, so a
  // point file converted again was not the same file.
  s.push_back({0, 0, 0}, {0.4783956904506592, -0.8758724092033074, -0.06312753879750849});
  for (int i = 1; i <= 200; ++i) {
    s.push_back({1.0 * i, 0, 0},
                SafeNormalize(Vec3{std::sin(i * 1.7), std::cos(i * 0.3), 0.01 * i}));
  }
  char dir[] = "/tmp/footfall-points-XXXXXX";
  REQUIRE(mkdtemp(dir));
  const std::string path = std::string(dir) + "/out.pts";
  std::string error;
  REQUIRE(WritePointFile(path, s, &error) == Status::kOk);
  RawSamples back;
  REQUIRE(ReadPointFile(path, &back, &error) == Status::kOk);
  REQUIRE(back.size() == s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    INFO("sample " << i);
    CHECK(back.points[i] == s.points[i]);
    CHECK(back.normals[i] == s.normals[i]);
  }
  std::remove(path.c_str());
  rmdir(dir);
}

TEST_CASE("WritePointFile writes a file of many runs in order", "[terrain][point_file]") {
  // Runs of 20,000 samples are formatted on several threads: 70,001 samples cross four runs,
  // the last one short.
  RawSamples s;
  for (int i = 0; i < 70001; ++i)
    s.push_back({i * 0.25, std::sin(i * 0.01), -i / 3.0}, Normalize(Vec3{0.1, 1, 0.001 * i}));
  char dir[] = "/tmp/footfall-points-XXXXXX";
  REQUIRE(mkdtemp(dir));
  const std::string path = std::string(dir) + "/many.pts";
  std::string error;
  REQUIRE(WritePointFile(path, s, &error) == Status::kOk);
  RawSamples back;
  REQUIRE(ReadPointFile(path, &back, &error) == Status::kOk);
  std::remove(path.c_str());
  rmdir(dir);
  REQUIRE(back.size() == s.size());
  CHECK(back.points == s.points);
  CHECK(back.normals == s.normals);
}

TEST_CASE("ReadPointFile reads every sample whatever its header's count says",
          "[terrain][point_file]") {
  // The header footfall writes gives the count, taken to reserve room; a header counting too
  // few, far too many or in another form, or none, reads the same samples.
  std::string body;
  for (int i = 0; i < 1000; ++i)
    body += std::to_string(i) + " " + std::to_string(i % 7) + " 0.5 0 1 0\n";
  char dir[] = "/tmp/footfall-points-XXXXXX";
  REQUIRE(mkdtemp(dir));
  const std::string path = std::string(dir) + "/in.pts";
  const std::string headers[] = {
      "# footfall terrain points: x y z nx ny nz (1000 samples)\n",
      "# footfall terrain points: x y z nx ny nz (5 samples)\n",
      "# footfall terrain points: x y z nx ny nz (1000000000000 samples)\n",
      "# footfall terrain points: x y z nx ny nz (18446744073709551616 samples)\n",
      "# footfall terrain points: (-3 samples)\n",
      "# (1000 samples)\n",
      ""};
  for (const std::string& header : headers) {
    INFO(header);
    FILE* f = std::fopen(path.c_str(), "wb");
    REQUIRE(f);
    std::fputs((header + body).c_str(), f);
    std::fclose(f);
    RawSamples s;
    std::string error;
    REQUIRE(ReadPointFile(path, &s, &error) == Status::kOk);
    REQUIRE(s.size() == 1000);
    CHECK(s.points[999] == Vec3{999, 999 % 7, 0.5});
    CHECK(s.points.capacity() < 100000);  // not the header's 1e12
  }
  std::remove(path.c_str());
  rmdir(dir);
}

TEST_CASE("ReadDecimal reads decimal numbers only, tiny ones as zero", "[terrain][decimal]") {
  double v = -1;
  CHECK(ReadDecimal("0.25", &v) == DecimalRead::kNumber);
  CHECK(v == 0.25);
  CHECK(ReadDecimal("+5e-1", &v) == DecimalRead::kNumber);
  CHECK(v == 0.5);
  CHECK(ReadDecimal("-.5", &v) == DecimalRead::kNumber);
  CHECK(v == -0.5);
  CHECK(ReadDecimal("1.", &v) == DecimalRead::kNumber);
  CHECK(v == 1);
  CHECK(ReadDecimal("-1e-400", &v) == DecimalRead::kNumber);
  CHECK(v == 0);
  CHECK(std::signbit(v));
  CHECK(ReadDecimal("1e400", &v) == DecimalRead::kTooLarge);
  // Too small or too large by the power of ten of the first non-zero digit, whatever the
  // leading zeros and the exponent's sign ("00.000...1" was said to be out of range).
  const std::string zeros(400, '0');
  for (const std::string& tiny : std::initializer_list<std::string>{
           "00.0" + zeros + "1", "-0.0" + zeros + "1e+5", "." + zeros + "1",
           "+0" + zeros + ".0" + zeros + "1", "1e-99999999999999999999", "100e-326"}) {
    INFO(tiny);
    v = 7;
    CHECK(ReadDecimal(tiny, &v) == DecimalRead::kNumber);
    CHECK(v == 0);
    CHECK(std::signbit(v) == (tiny[0] == '-'));
  }
  for (const std::string& huge : std::initializer_list<std::string>{
           "00" + zeros + "1" + zeros, "0.1e400", "-0.0" + zeros + "1e+800",
           "1e99999999999999999999", "1" + zeros + "e-10"}) {
    INFO(huge);
    CHECK(ReadDecimal(huge, &v) == DecimalRead::kTooLarge);
  }
  for (const char* bad : {"0x10", "0X1p3", "+-1", "++1", "1,5", "1.5.", "", "+", "-", "e5", "1e"}) {
    INFO(bad);
    CHECK(ReadDecimal(bad, &v) == DecimalRead::kNotANumber);
  }
  CHECK_FALSE(ParseFiniteDecimal("inf", &v));
  CHECK_FALSE(ParseFiniteDecimal("nan", &v));
  v = 7;
  CHECK_FALSE(ParseFiniteDecimal("12abc", &v));
  CHECK(v == 7);
  CHECK(ParseFiniteDecimal("-3.5e2", &v));
  CHECK(v == -350);
}

TEST_CASE("WholeNumberProblem takes decimal digits within the range only", "[terrain][decimal]") {
  CHECK(WholeNumberProblem("1", 1, 64).empty());
  CHECK(WholeNumberProblem("64", 1, 64).empty());
  CHECK(WholeNumberProblem("007", 0, 10).empty());
  CHECK(WholeNumberProblem("0", 1, 64) == "'0' is not a whole number from 1 to 64");
  CHECK(WholeNumberProblem("65", 1, 64) == "'65' is not a whole number from 1 to 64");
  for (const char* bad :
       {"", "1.5", "-1", "+5", " 5", "5 ", "1e3", "0x10", "nan", "9999999999999999999999"})
    CHECK(WholeNumberProblem(bad, 0, 100) ==
          "'" + std::string(bad) + "' is not a whole number from 0 to 100");
}
