#include "footfall/import/height_map.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "footfall/import/terrain_loader.h"
#include "test_support.h"

namespace footfall {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

const char* kAsc =
    "ncols 3\nnrows 2\nxllcorner 100\nyllcorner 200\ncellsize 2\nNODATA_value -9999\n"
    "1 2 3\n4 -9999 6\n";

}  // namespace

TEST_CASE("ReadAscGrid: header, values and NODATA", "[import][heightmap]") {
  test::TempDir dir;
  HeightMap map;
  std::string error;
  REQUIRE(ReadAscGrid(dir.Write("a.asc", kAsc), &map, &error) == Status::kOk);
  CHECK(map.cols == 3);
  CHECK(map.rows == 2);
  CHECK(map.cell_size == 2);
  CHECK(map.heights[5] == 6);
  CHECK(map.ValidCount() == 5);
  CHECK(map.valid[4] == 0);

  TriangleMesh mesh;
  REQUIRE(HeightMapToMesh(map, HeightMapFrame{2, 1, 'y'}, &mesh, &error) == Status::kOk);
  CHECK(mesh.vertices.size() == 5);   // the NODATA cell is left out
  CHECK(mesh.triangles.size() == 2);  // each square has three valid cells: one triangle each
  for (size_t t = 0; t < mesh.triangles.size(); ++t) CHECK(TriangleCross(mesh, t).y > 0);
  CHECK(mesh.vertices[0] == Vec3{0, 1, 0});
  CHECK(mesh.vertices[3] == Vec3{0, 4, 2});  // row 1 lies south (+z)
}

TEST_CASE("HeightMapToMesh: the up axis", "[import][heightmap]") {
  HeightMap map;
  map.cols = 2, map.rows = 2, map.heights = {1, 2, 3, 4}, map.valid = {1, 1, 1, 1};
  std::string error;
  for (char axis : {'x', 'y', 'z'}) {
    TriangleMesh mesh;
    REQUIRE(HeightMapToMesh(map, HeightMapFrame{1, 10, axis}, &mesh, &error) == Status::kOk);
    const Vec3& se = mesh.vertices[3];  // row 1, col 1, height 40
    if (axis == 'y') CHECK(se == Vec3{1, 40, 1});
    if (axis == 'z') CHECK(se == Vec3{1, -1, 40});
    if (axis == 'x') CHECK(se == Vec3{40, 1, -1});
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Vec3 n = TriangleCross(mesh, t);
      CHECK((axis == 'x' ? n.x : axis == 'y' ? n.y : n.z) > 0);
    }
  }
  TriangleMesh mesh;
  CHECK(HeightMapToMesh(map, HeightMapFrame{1, 1, 'w'}, &mesh, &error) == Status::kInvalidArgument);
}

TEST_CASE("ReadPgm: 8 and 16 bit binary and ASCII agree", "[import][heightmap]") {
  test::TempDir dir;
  HeightMap p5_8, p5_16, p2;
  std::string error;
  const std::string bytes8 = std::string("P5\n# comment\n3 2\n255\n") + '\x01' + '\x02' + '\x03' +
                             '\x04' + '\x05' + '\xff';
  const std::string bytes16 = std::string("P5 3 2 1000\n") + std::string(
                                                                 "\x00\x01\x00\x02\x00\x03"
                                                                 "\x00\x04\x00\x05\x00\xff",
                                                                 12);
  REQUIRE(ReadPgm(dir.Write("a.pgm", bytes8), &p5_8, &error) == Status::kOk);
  REQUIRE(ReadPgm(dir.Write("b.pgm", bytes16), &p5_16, &error) == Status::kOk);
  REQUIRE(ReadPgm(dir.Write("c.pgm", "P2\n3 2\n300\n1 2 3\n4 5 255\n"), &p2, &error) ==
          Status::kOk);
  const std::vector<double> expected{1, 2, 3, 4, 5, 255};
  CHECK(p5_8.heights == expected);
  CHECK(p5_16.heights == expected);
  CHECK(p2.heights == expected);
}

TEST_CASE("Height maps: bad files give clear errors", "[import][heightmap]") {
  test::TempDir dir;
  HeightMap map;
  std::string error;
  CHECK(ReadAscGrid(dir.Write("cut.asc",
                              "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
                              "1 2 3\n4\n"),
                    &map, &error) == Status::kParseError);
  CHECK(Contains(error, "cut.asc:7: truncated: expected 6 values (2 rows of 3), found 4"));
  CHECK(ReadAscGrid(dir.Write("bad.asc", "ncols 2\nnrows 1\ncellsize 1\n1 x\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "bad.asc:4: value 'x' is not a finite number"));
  CHECK(ReadAscGrid(dir.Write("hdr.asc", "ncols 2\nrows 1\n1 2\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "hdr.asc:2: unknown header 'rows'"));
  CHECK(ReadPgm(dir.Write("cut.pgm", std::string("P5 4 4 255\n") + std::string(10, 'a')), &map,
                &error) == Status::kParseError);
  CHECK(Contains(error, "cut.pgm: truncated: 4 x 4 pixels of 1 bytes need 16 bytes"));
  CHECK(ReadPgm(dir.Write("magic.pgm", "P6 1 1 255\nabc"), &map, &error) == Status::kParseError);
  CHECK(Contains(error, "magic.pgm:1: expected the PGM magic"));
  CHECK(ReadPgm(dir.File("absent.pgm"), &map, &error) == Status::kIoError);
  // Grey levels are whole numbers.
  CHECK(ReadPgm(dir.Write("half.pgm", "P2 2 1 255\n1 1.5\n"), &map, &error) == Status::kParseError);
  CHECK(Contains(error, "half.pgm:2: grey level '1.5' is not a whole number from 0 to maxval"));
  // A file that does not start as its format does is refused before it is read whole (a 2 GB
  // file of NUL bytes took 2 GB to say "out of memory").
  CHECK(ReadAscGrid(dir.Write("nul.asc", std::string(4096, '\0')), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "nul.asc:1: expected the grid header's first key ('ncols N'), found no "
                 "word within its first 256 bytes"));
  CHECK(ReadAscGrid(dir.Write("num.asc", "1 2 3\n"), &map, &error) == Status::kParseError);
  CHECK(Contains(error, "num.asc:1: expected the grid header's first key ('ncols N'), found '1'"));
  CHECK(ReadPgm(dir.Write("nul.pgm", std::string(4096, '\0')), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "nul.pgm:1: expected the PGM magic"));
}

TEST_CASE("Height maps far taller than their cells are refused before they are cut",
          "[import][heightmap]") {
  test::TempDir dir;
  // 2 x 2 pixels of 16 bits at the default height scale (one unit per grey level): slivers one
  // unit wide and 65535 tall. Cut under the budget's limit alone, they took 80 s and 4.6 GB.
  RawSamples samples;
  std::string error;
  CHECK(LoadTerrain(dir.Write("tall.pgm", "P2\n2 2\n65535\n0 65535\n100 200\n"),
                    TerrainLoadOptions{}, &samples, &error) == Status::kLimitExceeded);
  CHECK(Contains(error, "tall.pgm: separation 1 would cut the mesh into more than"));
  CHECK(Contains(error, "check --height-scale and --cell-size"));
  CHECK(samples.size() == 0);
  // Heights of 1e14 at opposite corners of 1-unit cells: every triangle is a needle (1 wide,
  // 1e14 long), and the error says so.
  CHECK(LoadTerrain(dir.Write("needle.asc", "ncols 2\nnrows 2\ncellsize 1\n1e14 0\n0 1e14\n"),
                    TerrainLoadOptions{}, &samples, &error) == Status::kParseError);
  CHECK(Contains(error, "needle.asc: all 2 triangles of the grid are degenerate"));
  // Scaled to metres of a 1 m grid, the same file loads.
  TerrainLoadOptions scaled;
  scaled.height_scale = 1e-4;
  REQUIRE(LoadTerrain(dir.File("tall.pgm"), scaled, &samples, &error) == Status::kOk);
  CHECK(samples.size() > 0);
}

TEST_CASE("Height maps: headers are checked against the data before anything is allocated",
          "[import][heightmap]") {
  test::TempDir dir;
  HeightMap map;
  std::string error;
  // A billion cells declared, three values present: refused at once (no 9 GB allocation).
  CHECK(ReadAscGrid(dir.Write("big.asc",
                              "ncols 1000000000\nnrows 1\nxllcorner 0\nyllcorner 0\n"
                              "cellsize 1\n1 2 3\n"),
                    &map, &error) == Status::kParseError);
  CHECK(Contains(
      error, "big.asc:6: truncated: expected 1000000000 values (1 rows of 1000000000), found 3"));
  CHECK(map.heights.capacity() == 0);
  CHECK(ReadPgm(dir.Write("big.pgm", "P5\n100000 100000\n255\nabc"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "big.pgm: truncated: 100000 x 100000 pixels of 1 bytes need 10000000000 bytes of "
                 "data, the file has 3"));
  CHECK(ReadPgm(dir.Write("big2.pgm", "P2\n# big\n100000 100000\n255\n1 2 3\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(
      error,
      "big2.pgm:5: truncated: expected 10000000000 grey levels (100000 x 100000 pixels), found 3"));
  // Sizes too large for an integer are printed as numbers (they overflowed to
  // -9223372036854775808).
  CHECK(ReadAscGrid(dir.Write("huge.asc", "ncols 1e30\nnrows 2\ncellsize 1\n1 2\n3 4\n"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error, "expected 2e+30 values (2 rows of 1e+30), found 4"));
  // A header within its data but beyond the cell cap: refused before the pixels are read (a
  // sparse file of 10001 x 10000 zero pixels, 100 MB that take no disk space).
  {
    const std::string header = "P5\n10001 10000\n255\n";
    const std::string path = dir.Write("huge.pgm", header);
    std::filesystem::resize_file(path, header.size() + size_t{10001} * 10000);
    CHECK(ReadPgm(path, &map, &error) == Status::kParseError);
    CHECK(Contains(error, "huge.pgm"));
    CHECK(Contains(error, "100000000 cells a height map may have"));
    CHECK(map.heights.capacity() == 0);
  }
  // P5 pixels above maxval are refused like P2 grey levels.
  CHECK(ReadPgm(dir.Write("over.pgm",
                          std::string("P5\n2 2\n100\n") + '\x01' + '\x02' + '\xff' + '\x04'),
                &map, &error) == Status::kParseError);
  CHECK(
      Contains(error, "over.pgm: pixel 2 (row 1, column 0, byte 13) is 255, above the maxval 100"));
  CHECK(ReadPgm(dir.Write("over16.pgm", std::string("P5 1 1 1000\n") + '\x03' + '\xe9'), &map,
                &error) == Status::kParseError);
  CHECK(Contains(error, "is 1001, above the maxval 1000"));
}

TEST_CASE("ReadAscGrid: a NODATA_value of NaN leaves out the NaN cells", "[import][heightmap]") {
  // As GDAL and R's terra write floating-point grids: was refused, "header 'NODATA_value' needs
  // a number on its line".
  test::TempDir dir;
  HeightMap map;
  std::string error;
  REQUIRE(ReadAscGrid(dir.Write("nan.asc",
                                "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\n"
                                "cellsize 1\nNODATA_value nan\nNaN 2 3\n4 -nan 6\n"),
                      &map, &error) == Status::kOk);
  CHECK(map.ValidCount() == 4);
  CHECK(map.valid[0] == 0);
  CHECK(map.valid[4] == 0);
  CHECK(map.heights[5] == 6);
  // A NaN cell is still refused when NODATA is a number, or not given.
  CHECK(ReadAscGrid(dir.Write("num.asc",
                              "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\n"
                              "cellsize 1\nNODATA_value -9999\n1 nan\n"),
                    &map, &error) == Status::kParseError);
  CHECK(Contains(error, "num.asc:7: value 'nan' is not a finite number"));
  // NaN names only NODATA: no other header takes it.
  CHECK(ReadAscGrid(dir.Write("cell.asc",
                              "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\n"
                              "cellsize nan\n1 1\n"),
                    &map, &error) == Status::kParseError);
  CHECK(Contains(error, "cell.asc:5: header 'cellsize': 'nan' is not a finite number"));
  // Said as what it is (each was "needs a number on its line", "truncated" or "more values"
  // than shown).
  CHECK(ReadAscGrid(dir.Write("inf.asc",
                              "ncols 3\nnrows 1\ncellsize 1\nNODATA_value 1.#INF\n"
                              "1 2 3\n"),
                    &map, &error) == Status::kParseError);
  CHECK(Contains(error,
                 "inf.asc:4: header 'NODATA_value': '1.#INF' is not a finite number "
                 "(Microsoft C's NaN or infinity) (NODATA_value may be a number or NaN)"));
  CHECK(ReadAscGrid(dir.Write("commas.asc", "ncols 4\nnrows 2\ncellsize 1\n1,2,3,4\n5,6,7,8\n"),
                    &map, &error) == Status::kParseError);
  CHECK(Contains(error,
                 "commas.asc:4: value '1,2,3,4' is not a finite number (values are "
                 "separated by spaces or tabs, not commas)"));
  CHECK(ReadAscGrid(dir.Write("decimal.asc", "ncols 2\nnrows 1\ncellsize 0,5\n1 2\n"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error,
                 "decimal.asc:3: header 'cellsize': '0,5' is not a finite number (a "
                 "decimal comma: write a decimal point, as in 1.5)"));
  CHECK(ReadAscGrid(dir.Write("eof.asc", "ncols 2\nnrows 1\ncellsize 1\n1 2\n\x1a"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error,
                 "eof.asc:5: more than the 2 values the header declares: '?' (bytes 1A) follows "
                 "them"));
}

TEST_CASE("ReadAscGrid: a bad first value is named as a value", "[import][heightmap]") {
  // It was taken for a header key: "unknown header '1e999' (expected ncols, ...)".
  test::TempDir dir;
  HeightMap map;
  std::string error;
  for (const std::string first : {"1e999", "nan", "-inf", "Infinity", "1x", ".5.5"}) {
    INFO(first);
    CHECK(ReadAscGrid(dir.Write("first.asc",
                                "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\n"
                                "cellsize 1\n" +
                                    first + " 1\n"),
                      &map, &error) == Status::kParseError);
    CHECK(Contains(error, "first.asc:6: value '" + first + "' is not a finite number"));
  }
}

TEST_CASE("Height maps: a UTF-8 byte order mark is skipped", "[import][heightmap]") {
  test::TempDir dir;
  HeightMap map;
  std::string error;
  REQUIRE(ReadAscGrid(dir.Write("bom.asc", std::string("\xEF\xBB\xBF") + kAsc), &map, &error) ==
          Status::kOk);
  CHECK(map.heights[5] == 6);
  REQUIRE(ReadPgm(dir.Write("bom.pgm", "\xEF\xBB\xBFP2\n2 1\n9\n1 2\n"), &map, &error) ==
          Status::kOk);
  CHECK(map.heights[1] == 2);
}

TEST_CASE("Height maps: UTF-16 text is refused as such", "[import][heightmap]") {
  // Was "expected the grid header's first key ('ncols N'), found '??n?c?'".
  test::TempDir dir;
  HeightMap map;
  std::string error;
  CHECK(ReadAscGrid(dir.Write("wide.asc", std::string("\xFF\xFEn\0c\0o\0l\0s\0", 12)), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error,
                 "/wide.asc:1: UTF-16 text (expected ASCII or UTF-8: save the file as UTF-8)"));
  CHECK(ReadPgm(dir.Write("wide.pgm", std::string("\xFE\xFF\0P\0"
                                                  "2\0\n",
                                                  8)),
                &map, &error) == Status::kParseError);
  CHECK(Contains(error,
                 "/wide.pgm:1: UTF-16 text (expected ASCII or UTF-8: save the file as UTF-8)"));
}

TEST_CASE("ReadPgm: bytes after a binary image's pixels are refused", "[import][heightmap]") {
  test::TempDir dir;
  HeightMap map;
  std::string error;
  const std::string pixels("\x01\x02\x03\x04\x05\x06", 6);
  SECTION("a header ended in CR LF is refused: its LF would be read as the first pixel") {
    CHECK(ReadPgm(dir.Write("crlf.pgm", "P5\r\n3 2\r\n255\r\n" + pixels), &map, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "crlf.pgm:3: the maxval is followed by CR LF"));
  }
  SECTION("a second image or other data after the pixels is refused") {
    CHECK(ReadPgm(dir.Write("two.pgm", "P5\n3 2\n255\n" + pixels + "P5\n3 2\n255\n" + pixels), &map,
                  &error) == Status::kParseError);
    CHECK(Contains(error, "two.pgm: 17 bytes after the 3 x 2 pixels' 6 bytes of data"));
  }
  SECTION("a line break after the pixels is read past") {
    REQUIRE(ReadPgm(dir.Write("nl.pgm", "P5\n3 2\n255\n" + pixels + "\n"), &map, &error) ==
            Status::kOk);
    CHECK(map.heights == std::vector<double>{1, 2, 3, 4, 5, 6});
  }
  SECTION("a CR LF header whose file holds exactly the pixels is read as written") {
    // The byte after the maxval's CR is the first pixel (10, a LF), as the format says.
    REQUIRE(ReadPgm(dir.Write("exact.pgm", "P5\n3 2\n255\r\n" + pixels.substr(1)), &map, &error) ==
            Status::kOk);
    CHECK(map.heights == std::vector<double>{10, 2, 3, 4, 5, 6});
  }
}

TEST_CASE("LoadTerrain: height maps with NODATA are resampled over the valid cells",
          "[import][heightmap]") {
  test::TempDir dir;
  std::string asc = "ncols 10\nnrows 10\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -1\n";
  for (int r = 0; r < 10; ++r) {
    for (int c = 0; c < 10; ++c) asc += (c >= 5 ? "-1 " : "2 ");
    asc += "\n";
  }
  TerrainLoadOptions options;
  options.separation = 0.5;
  RawSamples samples;
  std::string error;
  TerrainLoadReport report;
  REQUIRE(LoadTerrain(dir.Write("half.asc", asc), options, &samples, &error, &report) ==
          Status::kOk);
  CHECK(report.format == "heightmap");
  CHECK(report.nodata_cells == 50);
  CHECK(report.area == Approx(4 * 9));  // columns 0..4 span 4 cells, rows 9
  CHECK(report.bounds_max.x <= 4);
  for (size_t i = 0; i < samples.size(); ++i) {
    CHECK(samples.points[i].y == Approx(2));
    CHECK(samples.normals[i].y == Approx(1));
  }
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadAscGrid: rows of unequal length are refused at their line", "[import][heightmap]") {
  // A short row and a long one added up to the header's count and the grid loaded shifted,
  // silently.
  test::TempDir dir;
  HeightMap map;
  std::string error;
  const std::string header = "ncols 3\nnrows 3\ncellsize 1\n";
  CHECK(ReadAscGrid(dir.Write("short.asc", header + "1 2 3\n4 5\n6 7 8 9\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "short.asc:5: 2 values, expected 3 (ncols 3, one row per line)"));
  CHECK(ReadAscGrid(dir.Write("long.asc", header + "1 2 3 4\n5 6\n7 8 9\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "long.asc:4: 4 values, expected 3 (ncols 3, one row per line)"));
  CHECK(ReadAscGrid(dir.Write("end.asc", header + "1 2 3\n4 5 6\n7 8 9 10\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "end.asc:6: 4 values, expected 3 (ncols 3, one row per line)"));
  // Rows wrapped over lines, as long as every row is wrapped alike, and blank lines, are read.
  REQUIRE(ReadAscGrid(dir.Write("wrap.asc", header + "1 2\n3\n\n4 5\n6\n7 8 \r\n9\n"), &map,
                      &error) == Status::kOk);
  CHECK(map.heights[8] == 9);
  CHECK(ReadAscGrid(dir.Write("wrapbad.asc", header + "1 2\n3\n4\n5 6\n7 8\n9\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "wrapbad.asc:6: 1 value, expected 2 (ncols 3, each row on lines of 2 "
                 "and 1 values as the first row)"));
  // Values that run on over rows, the same number to a line but the last (all on one line, or
  // wrapped at a fixed width), can only be counted: they are read.
  for (const std::string data :
       {"1 2 3 4 5 6 7 8 9\n", "1 2 3 4\n5 6 7 8\n9\n", "1 2\n3 4\n5 6\n7 8\n9"}) {
    INFO(data);
    REQUIRE(ReadAscGrid(dir.Write("run.asc", header + data), &map, &error) == Status::kOk);
    CHECK(map.heights[8] == 9);
  }
  CHECK(ReadAscGrid(dir.Write("run.asc", header + "1 2 3 4\n5 6 7\n8 9\n"), &map, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "run.asc:4: 4 values, expected 3 (ncols 3, one row per line)"));
}

TEST_CASE("ReadAscGrid: Microsoft C's NaN is read as NaN", "[import][heightmap]") {
  // As "nan": a NaN NODATA_value leaves such cells out; elsewhere it is not a finite number.
  test::TempDir dir;
  HeightMap map;
  std::string error;
  REQUIRE(ReadAscGrid(dir.Write("nan.asc",
                                "ncols 2\nnrows 1\ncellsize 1\n"
                                "NODATA_value -1.#QNAN\n-1.#IND 2\n"),
                      &map, &error) == Status::kOk);
  CHECK(map.ValidCount() == 1);
  CHECK(ReadAscGrid(dir.Write("inf.asc", "ncols 2\nnrows 1\ncellsize 1\n1 1.#INF\n"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error,
                 "inf.asc:4: value '1.#INF' is not a finite number (Microsoft C's NaN or "
                 "infinity)"));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadAscGrid: a '#' comment is named as one", "[import][heightmap]") {
  // It was "header '#' needs a number on its line", or among the values a row too long.
  test::TempDir dir;
  HeightMap map;
  std::string error;
  for (const std::string& text :
       {std::string("ncols 2\nnrows 2\ncellsize 1\n# heights in metres\n1 2\n3 4\n"),
        std::string("ncols 2\nnrows 2\ncellsize 1 # metres\n1 2\n3 4\n"),
        std::string("ncols 2\nnrows 2\ncellsize 1\n1 2\n3 4\n# end\n")}) {
    INFO(text);
    CHECK(ReadAscGrid(dir.Write("c.asc", text), &map, &error) == Status::kParseError);
    CHECK(Contains(error, "' starts a comment, which ESRI ASCII grids do not have"));
  }
  CHECK(ReadAscGrid(dir.Write("c.asc", "ncols 2\nnrows 2\ncellsize 1\n1 2 # row 1\n3 4\n"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error, "c.asc:4: '#' starts a comment, which ESRI ASCII grids do not have"));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadAscGrid: GDAL's DX and DY give the cell size when equal", "[import][heightmap]") {
  // They were "unknown header 'DX'", though GDAL writes them for its grids.
  test::TempDir dir;
  HeightMap map;
  std::string error;
  const std::string data = "1 2\n3 4\n";
  REQUIRE(ReadAscGrid(dir.Write("d.asc", "ncols 2\nnrows 2\nDX 0.5\nDY 0.5\n" + data), &map,
                      &error) == Status::kOk);
  CHECK(map.cell_size == 0.5);
  const std::pair<std::string, std::string> cases[] = {
      {"DX 0.5\nDY 0.25\n", "d.asc:4: DX and DY differ (expected cellsize, or DX and DY equal"},
      {"DX 0.5\n", "d.asc:3: DX and DY come together"},
      {"cellsize 1\nDY 0.5\n", "d.asc:4: cellsize and DX/DY both given"},
  };
  for (const auto& [header, expected] : cases) {
    CHECK(ReadAscGrid(dir.Write("d.asc", "ncols 2\nnrows 2\n" + header + data), &map, &error) ==
          Status::kParseError);
    CHECK(Contains(error, expected));
  }
}

}  // namespace footfall

namespace footfall {
namespace {

// The peak resident memory of this process so far, in bytes.
long PeakResidentBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss * 1024L;
}

}  // namespace

TEST_CASE("Height maps: a grid too large is refused from its header, before the file is read",
          "[import][heightmap]") {
  // A 3 GB image declaring 60000 x 50000 pixels took 29 s and 6 GB of memory to be refused:
  // the file was read whole before its header was looked at. Sparse files: no disk space.
  test::TempDir dir;
  HeightMap map;
  std::string error;
  constexpr size_t kBytes = size_t{3} << 30;
  const long peak_before = PeakResidentBytes();
  {
    const std::string header = "P5\n60000 50000\n255\n";
    const std::string path = dir.Write("wide.pgm", header);
    std::filesystem::resize_file(path, header.size() + kBytes);
    CHECK(ReadPgm(path, &map, &error) == Status::kParseError);
    CHECK(Contains(error,
                   "wide.pgm:2: the header declares 60000 x 50000 pixels, more than the "
                   "100000000 cells a height map may have"));
  }
  {
    const std::string header = "ncols 20000\nnrows 20000\ncellsize 1\n";
    std::string row;
    for (int i = 0; i < 20000; ++i) row += "0 ";
    const std::string path = dir.Write("wide.asc", header + row + "\n");
    std::filesystem::resize_file(path, header.size() + kBytes);
    CHECK(ReadAscGrid(path, &map, &error) == Status::kParseError);
    CHECK(Contains(error,
                   "wide.asc:2: the header declares 400000000 values (20000 rows of "
                   "20000), more than the 100000000 cells a height map may have"));
  }
  // A small grid followed by gigabytes (of NUL bytes here): refused from its size too (it was
  // read whole, 2 x its size in memory, before "more values than the header declares").
  for (const std::string& header :
       {std::string("ncols 2\nnrows 2\ncellsize 1\n1 2\n3 4\n"),
        std::string("P2\n2 2\n255\n1 2 3 4\n"), std::string("P5\n2 2\n255\n\x01\x02\x03\x04")}) {
    const std::string path = dir.Write(header[0] == 'P' ? "tail.pgm" : "tail.asc", header);
    std::filesystem::resize_file(path, header.size() + kBytes);
    INFO(header);
    CHECK((header[0] == 'P' ? ReadPgm(path, &map, &error) : ReadAscGrid(path, &map, &error)) ==
          Status::kParseError);
    CHECK(Contains(error, ": 3221225"));
    CHECK(Contains(error, "bytes, far more than "));
    CHECK(Contains(error, "data past the grid (check the header's size)"));
  }
  CHECK(PeakResidentBytes() - peak_before < (long{256} << 20));
}

TEST_CASE("Height maps: a file too large for memory is named, not a bare out of memory",
          "[import][heightmap]") {
  // A small header over 3 GB of data, read in a child process limited to 1 GB of address space.
  test::TempDir dir;
  const std::string header = "ncols 2\nnrows 2\ncellsize 1\n";
  const std::string path = dir.Write("long.asc", header + "1 2\n3 4\n");
  std::filesystem::resize_file(path, size_t{3} << 30);
  int fds[2];
  REQUIRE(pipe(fds) == 0);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    close(fds[0]);
    rlimit limit{size_t{1} << 30, size_t{1} << 30};
    setrlimit(RLIMIT_AS, &limit);
    HeightMap map;
    std::string error;
    const Status status = ReadAscGrid(path, &map, &error);
    error = std::to_string(static_cast<int>(status)) + " " + error;
    if (write(fds[1], error.data(), error.size()) < 0) _exit(2);
    _exit(0);
  }
  close(fds[1]);
  std::string said;
  char buffer[4096];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) said.append(buffer, n);
  close(fds[0]);
  int wstatus = 0;
  waitpid(child, &wstatus, 0);
  CHECK(WIFEXITED(wstatus));
  CHECK(WEXITSTATUS(wstatus) == 0);
  INFO(said);
  // (It was "out of memory reading the file whole (3221225472 bytes"; the file's size alone
  // now refuses it, before it is read.)
  CHECK(Contains(said, std::to_string(static_cast<int>(Status::kParseError)) + " "));
  CHECK(Contains(said, "long.asc: 3221225472 bytes, far more than 4 values (2 rows of 2) needs"));
}

TEST_CASE("ReadAscGrid: a header line holds one key and one value", "[import][heightmap]") {
  // "cellsize 1 7 8" loaded with 7 8 as the grid's first row; "xllcorner 0 0" was "header
  // needs cellsize", "ncols 2 4" "header needs whole ncols and nrows".
  test::TempDir dir;
  HeightMap map;
  std::string error;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1 7 8\n1 2\n",
       "a.asc:5: header "
       "'cellsize' has more "
       "than one value"},
      {"ncols 2\nnrows 2\nxllcorner 0 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n",
       "a.asc:3: header 'xllcorner' has more than one value on its line"},
      {"ncols 2 4\nnrows 2\ncellsize 1\n1 2\n3 4\n", "a.asc:1: header 'ncols' has more"},
      {"ncols 3\nnrows 2\ncellsize 1\nNODATA_value -9999 7 8 9\n1 2 3\n4 5 6\n",
       "a.asc:4: header 'NODATA_value' has more"},
  };
  for (const auto& [text, expected] : cases) {
    INFO(text);
    CHECK(ReadAscGrid(dir.Write("a.asc", text), &map, &error) == Status::kParseError);
    CHECK(Contains(error, expected));
  }
}

TEST_CASE("ReadAscGrid: lines ended by CR alone are counted as lines", "[import][heightmap]") {
  // Every error of a classic Mac OS file was named at line 1.
  test::TempDir dir;
  HeightMap map;
  std::string error;
  CHECK(ReadAscGrid(dir.Write("cr.asc", "ncols 2\rnrows 2\rcellsize 1\r1 2\r3 x\r"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error, "cr.asc:5: value 'x' is not a finite number"));
  CHECK(ReadAscGrid(dir.Write("cr.asc", "ncols 2\rnrows 2\rcellsize 1\r1 2 5\r3 4\r"), &map,
                    &error) == Status::kParseError);
  CHECK(Contains(error, "cr.asc:4: 3 values, expected 2"));
  REQUIRE(ReadAscGrid(dir.Write("cr.asc", "ncols 2\rnrows 2\rcellsize 1\r1 2\r3 4\r"), &map,
                      &error) == Status::kOk);
  CHECK(map.heights == std::vector<double>{1, 2, 3, 4});
}

TEST_CASE("DescribeSkippedFaces: a phrase for faces left out, by format", "[import][heightmap]") {
  TerrainLoadReport report;
  report.format = "mesh";
  report.faces = 3;
  CHECK(DescribeSkippedFaces(report).empty());
  report.skipped_faces = 2;
  CHECK(DescribeSkippedFaces(report) ==
        "2 of 3 faces left out (a vertex used twice, a face listed again, or no area)");
  report.format = "heightmap";
  report.skipped_faces = 1;
  CHECK(DescribeSkippedFaces(report) ==
        "1 triangle of the grid left out, too thin for its length (check --height-scale and "
        "--cell-size)");
  report.skipped_faces = 4;
  CHECK(DescribeSkippedFaces(report).rfind("4 triangles of the grid left out, too thin for their",
                                           0) == 0);
}

}  // namespace footfall
