#include "footfall/import/mesh_reader.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/input_file.h"
#include "test_support.h"

namespace footfall {
namespace {

// A unit cube as a closed quad mesh, faces outward.
const char* kCubeObj =
    "# cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

Status Read(const std::string& path, TriangleMesh* mesh, std::string* error,
            MeshReadReport* report = nullptr) {
  return ReadMesh(path, mesh, error, report);
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

void CheckCube(const TriangleMesh& mesh) {
  CHECK(mesh.triangles.size() == 12);
  CHECK(SurfaceArea(mesh) == Approx(6));
  // Closed and facing out: every face normal points away from the centre.
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 c = (mesh.vertices[mesh.triangles[t][0]] + mesh.vertices[mesh.triangles[t][1]] +
                    mesh.vertices[mesh.triangles[t][2]]) /
                   3;
    CHECK(Dot(TriangleCross(mesh, t), c - Vec3{0.5, 0.5, 0.5}) > 0);
  }
}

}  // namespace

TEST_CASE("ReadMesh: every format gives the same triangulated cube", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  SECTION("OBJ with quads") {
    REQUIRE(Read(dir.Write("cube.obj", kCubeObj), &mesh, &error, &report) == Status::kOk);
    CHECK(report.vertices == 8);
    CHECK(report.faces == 6);
    CHECK(report.skipped_faces == 0);
    CheckCube(mesh);
  }
  SECTION("OFF") {
    const std::string off =
        "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
    REQUIRE(Read(dir.Write("cube.off", off), &mesh, &error) == Status::kOk);
    CheckCube(mesh);
  }
  SECTION("ASCII PLY") {
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
        "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
    REQUIRE(Read(dir.Write("cube.ply", ply), &mesh, &error) == Status::kOk);
    CheckCube(mesh);
  }
  SECTION("ASCII and binary STL, and OM written from the OBJ") {
    TriangleMesh cube;
    REQUIRE(Read(dir.Write("cube.obj", kCubeObj), &cube, &error) == Status::kOk);
    std::string ascii = "solid cube\n", binary(80, ' ');
    const uint32_t count = static_cast<uint32_t>(cube.triangles.size());
    binary.append(reinterpret_cast<const char*>(&count), 4);
    for (size_t t = 0; t < cube.triangles.size(); ++t) {
      const Vec3 n = Normalize(TriangleCross(cube, t));
      ascii += "facet normal " + std::to_string(n.x) + " " + std::to_string(n.y) + " " +
               std::to_string(n.z) + "\nouter loop\n";
      float f[12] = {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)};
      for (int c = 0; c < 3; ++c) {
        const Vec3& v = cube.vertices[cube.triangles[t][c]];
        ascii += "vertex " + std::to_string(v.x) + " " + std::to_string(v.y) + " " +
                 std::to_string(v.z) + "\n";
        f[3 + 3 * c] = static_cast<float>(v.x), f[4 + 3 * c] = static_cast<float>(v.y),
                  f[5 + 3 * c] = static_cast<float>(v.z);
      }
      ascii += "endloop\nendfacet\n";
      binary.append(reinterpret_cast<const char*>(f), sizeof f);
      binary.append(2, '\0');
    }
    ascii += "endsolid cube\n";
    REQUIRE(Read(dir.Write("ascii.stl", ascii), &mesh, &error) == Status::kOk);
    CheckCube(mesh);
    REQUIRE(Read(dir.Write("binary.stl", binary), &mesh, &error) == Status::kOk);
    CheckCube(mesh);
    SECTION("a truncated binary STL is refused") {
      CHECK(Read(dir.Write("cut.stl", binary.substr(0, binary.size() - 30)), &mesh, &error) ==
            Status::kParseError);
      CHECK(Contains(error, "cut.stl: truncated: binary STL declares 12 triangles"));
    }
  }
}

TEST_CASE("ReadMesh: degenerate faces are skipped and counted", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 2 0 0\n"
      "f 1 4 3\nf 1 3 2\nf 1 2 5\nf 2 2 3\n";  // 1 2 5 is collinear, 2 2 3 repeats a vertex
  REQUIRE(Read(dir.Write("degenerate.obj", obj), &mesh, &error, &report) == Status::kOk);
  CHECK(mesh.triangles.size() == 2);
  CHECK(report.skipped_faces == 2);
  CHECK(SurfaceArea(mesh) == Approx(1));
}

TEST_CASE("ReadMesh: reading meshes again and again holds no more memory", "[import][mesh]") {
  // OpenMesh's stream disconnect frees nothing: connecting its message streams for each read
  // leaked 96 bytes a mesh (4.8 MB over these reads).
  test::TempDir dir;
  const std::string path = dir.Write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n");
  auto resident_kb = [] {
    std::ifstream statm("/proc/self/statm");
    size_t pages = 0, resident = 0;
    statm >> pages >> resident;
    return resident * (static_cast<size_t>(sysconf(_SC_PAGESIZE)) / 1024);
  };
  auto read_many = [&](int n) {
    for (int i = 0; i < n; ++i) {
      TriangleMesh mesh;
      std::string error;
      REQUIRE(ReadMesh(path, &mesh, &error) == Status::kOk);
    }
  };
  read_many(2000);  // allocator and OpenMesh warmed up
  const size_t before = resident_kb();
  read_many(50000);
  CHECK(resident_kb() - before < 1024);
}

TEST_CASE("ReadMesh: bad meshes give clear errors", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  SECTION("empty file") {
    CHECK(Read(dir.Write("empty.obj", ""), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "empty.obj: the file is empty"));
  }
  SECTION("no face left, each said why") {
    // A square with a square hole, bridged through its own corners: said to be "degenerate
    // (zero area)", with an area of 12.
    const std::string keyhole =
        "v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nv 1 0 1\nv 1 0 3\nv 3 0 3\nv 3 0 1\n"
        "f 1 2 3 4 1 5 6 7 8 5\n";
    CHECK(Read(dir.Write("keyhole.obj", keyhole), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error,
                   "keyhole.obj: no face is left: 1 with a vertex used twice (a polygon "
                   "with a hole bridged through its own corners"));
    CHECK(Read(dir.Write("line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "line.obj: no face is left: 1 of no area (degenerate)"));
  }
  SECTION("lines ended by CR alone, in every text format") {
    // OBJ and OFF said so; PLY said "expected the header line 'ply'" and ASCII STL "no closing
    // 'endsolid'".
    const std::string ply =
        "ply\rformat ascii 1.0\relement vertex 3\rproperty float x\rproperty float y\r"
        "property float z\relement face 1\rproperty list uchar int vertex_indices\r"
        "end_header\r0 0 0\r1 0 0\r0 0 1\r3 0 1 2\r";
    const std::string stl =
        "solid t\rfacet normal 0 1 0\router loop\rvertex 0 0 0\rvertex 1 0 0\r"
        "vertex 0 0 1\rendloop\rendfacet\rendsolid t\r";
    for (const auto& [name, text] :
         {std::make_pair("cr.ply", ply), std::make_pair("cr.stl", stl)}) {
      INFO(name);
      CHECK(Read(dir.Write(name, text), &mesh, &error) == Status::kParseError);
      CHECK(Contains(error, "lines end in CR alone (classic Mac OS)"));
    }
  }
  SECTION("UTF-16 text") {
    // A UTF-16 OBJ read as "no vertices: the mesh is empty".
    const std::string obj(
        "\xFF\xFEv\0 \0"
        "0\0\n\0",
        10);
    CHECK(Read(dir.Write("wide.obj", obj), &mesh, &error) == Status::kParseError);
    CHECK(
        Contains(error, "wide.obj: UTF-16 text (expected ASCII or UTF-8: save the file as UTF-8)"));
    const std::string off("\xFE\xFF\0O\0F\0F\0\n", 10);
    CHECK(Read(dir.Write("wide.off", off), &mesh, &error) == Status::kParseError);
    CHECK(
        Contains(error, "wide.off: UTF-16 text (expected ASCII or UTF-8: save the file as UTF-8)"));
  }
  SECTION("vertices but no faces") {
    CHECK(Read(dir.Write("points.obj", "v 0 0 0\nv 1 0 0\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "no faces"));
  }
  SECTION("non-manifold edge") {
    const std::string obj =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    CHECK(Read(dir.Write("fin.obj", obj), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "fin.obj: the mesh is not manifold"));
    CHECK(!Contains(error, "one-sided"));
  }
  SECTION("a Moebius strip is said to be one-sided") {
    // Every edge joins two faces at most, but no winding of them all agrees (it was said to
    // share edges with two other faces).
    std::ostringstream obj;
    constexpr int kSegments = 60;
    for (int i = 0; i < kSegments; ++i) {
      const double t = 2 * 3.14159265358979 * i / kSegments;
      for (const double w : {-0.3, 0.3}) {
        const double r = 1 + w * std::cos(t / 2);
        obj << "v " << r * std::cos(t) << ' ' << w * std::sin(t / 2) << ' ' << r * std::sin(t)
            << '\n';
      }
    }
    for (int i = 0; i < kSegments; ++i) {
      const int a = 2 * i + 1, b = a + 1;
      // The last quad joins the first edge turned over.
      const int c = i + 1 < kSegments ? a + 2 : 2, d = i + 1 < kSegments ? b + 2 : 1;
      obj << "f " << a << ' ' << b << ' ' << d << ' ' << c << '\n';
    }
    CHECK(Read(dir.Write("moebius.obj", obj.str()), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "moebius.obj: the mesh is not manifold"));
    CHECK(Contains(error,
                   "or close a one-sided surface (a sheet whose faces cannot all be wound "
                   "one way, as on a Moebius strip)"));
  }
  SECTION("records beyond the declared counts") {
    // Declaring 2 faces and holding 4 loaded half the area without a word.
    CHECK(Read(dir.Write("more.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"), &mesh,
               &error) == Status::kParseError);
    CHECK(
        Contains(error, "more.off:7: a line after the 3 vertices and 1 faces the counts declare"));
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n3 0 2 1\n";
    CHECK(Read(dir.Write("more.ply", ply), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "more.ply:15: a record after the 4 the header declares"));
  }
  SECTION("a line longer than 1 MiB") {
    CHECK(Read(dir.Write("long.obj", "v 0 0 0\n" + std::string(kMaxLineBytes + 1, '\0')), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "long.obj:2: line longer than 1 MiB"));
    CHECK(Read(dir.Write("long.off", "OFF\n" + std::string(kMaxLineBytes + 1, 'x')), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "long.off:2: line longer than 1 MiB"));
    CHECK(Read(dir.Write("long.stl", "solid x\n" + std::string(kMaxLineBytes + 1, 'x')), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "long.stl:2: line longer than 1 MiB"));
  }
  SECTION("a binary STL whose header begins with 'solid', cut short") {
    std::string stl = "solid exported" + std::string(66, ' ');
    const uint32_t count = 2;
    stl.append(reinterpret_cast<const char*>(&count), 4);
    stl.append(50 + 40, '\0');  // a facet and most of another
    CHECK(Read(dir.Write("cut.stl", stl), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error,
                   "cut.stl: truncated: binary STL declares 2 triangles (184 bytes), the "
                   "file has 174 bytes"));
  }
  SECTION("NaN vertex") {
    CHECK(Read(dir.Write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "nan.obj:2: vertex coordinate 'nan' is not a finite number"));
    CHECK(Read(dir.Write("comma.obj", "v 0 0 0\nv 1,5 0 0\nv 0 1 0\nf 1 2 3\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error,
                   "comma.obj:2: vertex coordinate '1,5' is not a finite number (a "
                   "decimal comma: write a decimal point, as in 1.5)"));
    CHECK(Read(dir.Write("nan.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n"), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "nan.off:4:"));
  }
  SECTION("truncated files") {
    const std::string cube = kCubeObj;
    CHECK(Read(dir.Write("cut.obj", cube.substr(0, cube.size() - 5)), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "cut.obj:15: face has 2 vertices"));
    CHECK(Read(dir.Write("cut.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n"), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "cut.off: truncated: header declares 2 faces, found 1"));
    const std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n" +
        std::string(20, '\0');
    CHECK(Read(dir.Write("cut.ply", ply), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "cut.ply: truncated"));
    CHECK(Read(dir.Write("missing.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "missing.obj:3: face uses vertex 3 but only 2 vertices"));
  }
  SECTION("binary PLY and STL values are checked as the text formats' are") {
    // OpenMesh dropped a binary PLY face with an index out of range, and a binary STL facet
    // with a NaN vertex, silently: the rest loaded as if whole.
    auto ply = [](bool big_endian, float x0, int index) {
      std::string s = std::string("ply\nformat binary_") + (big_endian ? "big" : "little") +
                      "_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 2\nproperty list uchar int "
                      "vertex_indices\nend_header\n";
      auto put = [&](const void* p, size_t n) {
        std::string bytes(static_cast<const char*>(p), n);
        if (big_endian) std::reverse(bytes.begin(), bytes.end());
        s += bytes;
      };
      const float v[4][3] = {{x0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
      for (const auto& p : v)
        for (float c : p) put(&c, 4);
      const int faces[2][3] = {{0, 2, 1}, {0, 3, index}};
      for (const auto& f : faces) {
        s += '\3';
        for (int i : f) put(&i, 4);
      }
      return s;
    };
    REQUIRE(Read(dir.Write("good.ply", ply(false, 0, 2)), &mesh, &error) == Status::kOk);
    CHECK(mesh.triangles.size() == 2);
    REQUIRE(Read(dir.Write("big.ply", ply(true, 0, 2)), &mesh, &error) == Status::kOk);
    CHECK(mesh.triangles.size() == 2);
    CHECK(Read(dir.Write("index.ply", ply(true, 0, 1000000)), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "index.ply: face 2: vertex index 1000000 is not an index below 4"));
    CHECK(Read(dir.Write("nan.ply", ply(false, std::nanf(""), 2)), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "nan.ply: vertex 1: coordinate x is NaN, infinite or beyond +-5e14"));
    std::string stl(80, ' ');
    const uint32_t count = 2;
    stl.append(reinterpret_cast<const char*>(&count), 4);
    const float facets[2][12] = {{0, 1, 0, std::nanf(""), 0, 0, 0, 0, 1, 1, 0, 0},
                                 {0, 1, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1}};
    for (const auto& f : facets) {
      stl.append(reinterpret_cast<const char*>(f), sizeof f);
      stl.append(2, '\0');
    }
    CHECK(Read(dir.Write("nan.stl", stl), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "nan.stl: facet 1: a vertex coordinate is NaN"));
    CHECK(Read(dir.Write("long.stl", stl + "xx"), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error,
                   "long.stl: extra bytes: binary STL declares 2 triangles (184 bytes), "
                   "the file has 186 bytes"));
  }
  SECTION("ASCII STL facets are triangles") {
    // OpenMesh kept the first three vertices of a four-vertex loop and dropped the fourth.
    const std::string quad =
        "solid q\nfacet normal 0 1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 0 1\n"
        "vertex 0 0 1\nendloop\nendfacet\nendsolid q\n";
    CHECK(Read(dir.Write("quad.stl", quad), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "quad.stl:8: facet loop has 4 vertices, expected 3"));
  }
  SECTION("ASCII PLY values are checked line by line") {
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    // Each used to read as "3 vertices but no faces".
    CHECK(Read(dir.Write("nan.ply", header + "nan 0 0\n1 0 0\n0 0 1\n3 0 1 2\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "nan.ply:10: vertex coordinate 'nan' is not a finite number"));
    CHECK(Read(dir.Write("index.ply", header + "0 0 0\n1 0 0\n0 0 1\n3 0 1 9\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "index.ply:13: face vertex '9' is not an index below 3"));
    CHECK(Read(dir.Write("short.ply", header + "0 0 0\n1 0 0\n0 0 1\n5 0 1 2\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "short.ply:13: list 'vertex_indices' needs its count and that many"));
    REQUIRE(Read(dir.Write("good.ply", header + "0 0 0\n1 0 0\n0 0 1\n3 0 1 2\n"), &mesh, &error) ==
            Status::kOk);
    CHECK(mesh.triangles.size() == 1);
  }
  SECTION("OFF variants are checked as OFF; other dimensions, binary OFF and .om are refused") {
    // A NOFF whose header claims 2e9 faces took 8 GB in OpenMesh before this check.
    const std::string noff =
        "NOFF\n3 2000000000 0\n0 0 0 0 1 0\n1 0 0 0 1 0\n0 0 1 0 1 0\n3 0 1 2\n";
    CHECK(Read(dir.Write("huge.off", noff), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "huge.off: truncated: header declares 2000000000 faces, found 1"));
    CHECK(Read(dir.Write("nan.off",
                         "COFF\n3 1 0\n0 0 0 1 1 1\nnan 0 0 1 1 1\n0 1 0 1 1 1\n"
                         "3 0 1 2\n"),
               &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "nan.off:4: vertex coordinate 'nan' is not a finite number"));
    const std::string cnoff =
        "CNOFF\n3 1 0\n0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 0 255 0\n0 1 0 0 0 1 0 0 255\n3 0 1 2\n";
    REQUIRE(Read(dir.Write("ok.off", cnoff), &mesh, &error) == Status::kOk);
    CHECK(mesh.vertices.size() == 3);
    CHECK(mesh.triangles.size() == 1);
    CHECK(Read(dir.Write("four.off", "4OFF\n1 0 0\n0 0 0 1\n"), &mesh, &error) ==
          Status::kParseError);
    CHECK(Contains(error, "four.off:1: '4OFF' files are not read"));
    CHECK(Read(dir.Write("bin.off", "OFF BINARY\n"), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "bin.off:1: binary OFF is not read"));
    // OpenMesh's own reader asserts (the process aborts) on this damaged .om header.
    std::string om("OMP\"\x00\xa3\xe1\x11\x00\xa3\xe1\x11\x00\xa3\xe1\x11", 16);
    om += std::string(8, '\0');
    RawSamples samples;
    CHECK(LoadTerrain(dir.Write("damaged.om", om), TerrainLoadOptions{}, &samples, &error) ==
          Status::kInvalidArgument);
    CHECK(Contains(error, "damaged.om: OpenMesh's .om format is not read"));
  }
  SECTION("missing file and unknown extension") {
    CHECK(Read(dir.File("absent.obj"), &mesh, &error) == Status::kIoError);
    CHECK(Contains(error, "absent.obj: cannot open"));
    RawSamples samples;
    CHECK(LoadTerrain(dir.Write("terrain.xyzw", "1 2 3"), TerrainLoadOptions{}, &samples, &error) ==
          Status::kInvalidArgument);
    CHECK(Contains(error, "unknown terrain file extension 'xyzw'"));
    // An empty path was named by nothing: ": cannot open terrain file: No such file ...".
    CHECK(LoadTerrain("", TerrainLoadOptions{}, &samples, &error) == Status::kInvalidArgument);
    CHECK(error == "cannot open terrain file: expected a path, got an empty one");
  }
}

TEST_CASE("LoadTerrain: meshes are resampled at the separation", "[import][mesh]") {
  test::TempDir dir;
  TerrainLoadOptions options;
  options.separation = 0.1;
  RawSamples samples;
  std::string error;
  TerrainLoadReport report;
  REQUIRE(LoadTerrain(dir.Write("cube.obj", kCubeObj), options, &samples, &error, &report) ==
          Status::kOk);
  CHECK(report.format == "mesh");
  CHECK(report.faces == 6);
  CHECK(report.area == Approx(6));
  CHECK(report.separation == 0.1);
  CHECK(report.samples == samples.size());
  CHECK(samples.size() > 0.9 * 6 / (0.1 * 0.1));  // fewer near the edges, where faces meet
  CHECK(report.bounds_min.x >= 0);
  CHECK(report.bounds_max.y <= 1);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: OBJ and OFF meshes keep double-precision coordinates far from the origin",
          "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  // In float, 300000.01 and 300000.02 are the same number (float spacing there is 0.03).
  const std::string obj = "v 300000.01 0 0\nv 300000.02 0 1\nv 300001.03 0 0\nf 1 2 3\n";
  const std::string off = "OFF\n3 1 0\n300000.01 0 0\n300000.02 0 1\n300001.03 0 0\n3 0 1 2\n";
  // PLY, STL and OM go through OpenMesh's float parsing (see the README).
  for (const auto& [name, text] :
       {std::pair<std::string, std::string>{"far.obj", obj}, {"far.off", off}}) {
    INFO(name);
    REQUIRE(Read(dir.Write(name, text), &mesh, &error) == Status::kOk);
    CHECK(mesh.vertices[0].x == 300000.01);
    CHECK(mesh.vertices[1].x == 300000.02);
    CHECK(mesh.vertices[2].x == 300001.03);
  }
}

TEST_CASE("ReadMesh: coordinates beyond kMaxCoordinate are refused with file and line",
          "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  CHECK(Read(dir.Write("huge.obj", "v 1 0 0\nv 0 0 1\nv 0 -1e300 0\nf 1 2 3\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "huge.obj:3: vertex coordinate -1e300 is out of range (expected "
                 "|coordinate| <= 5e+14)"));
  CHECK(Read(dir.Write("huge.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 0 6e14\n3 0 1 2\n"), &mesh,
             &error) == Status::kParseError);
  CHECK(Contains(error, "huge.off:5: vertex coordinate 6e14 is out of range"));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: OFF faces may carry a colour after their indices", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  // A 2 x 1 floor of quads: 'n i1 .. in' then nothing, a colour map index, R G B or R G B A.
  const std::string head = "OFF\n6 2 0\n0 0 0\n1 0 0\n2 0 0\n0 0 1\n1 0 1\n2 0 1\n";
  for (const std::string colour : {"", " 7", " 0.8 0.8 0.8", " 255 0 0", " 1 0.5 0 0.25"}) {
    INFO("colour '" << colour << "'");
    const std::string off = head + "4 0 3 4 1" + colour + "\n4 1 4 5 2" + colour + "\n";
    REQUIRE(Read(dir.Write("colour.off", off), &mesh, &error, &report) == Status::kOk);
    CHECK(report.faces == 2);
    CHECK(report.skipped_faces == 0);
    CHECK(mesh.triangles.size() == 4);
    CHECK(SurfaceArea(mesh) == Approx(2));
  }
  CHECK(Read(dir.Write("two.off", head + "4 0 3 4 1 1 2\n4 1 4 5 2\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "two.off:9: expected 4 vertex indices and then nothing or a colour (1, "
                 "3 or 4 numbers), found 2 values after the indices"));
  CHECK(Read(dir.Write("word.off", head + "4 0 3 4 1\n4 1 4 5 2 red\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "word.off:10: face colour value 'red' is not a number"));
}

TEST_CASE("ReadMesh: PLY elements are read in any order", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string ply =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "3 0 2 1\n0 0 0\n1 0 0\n0 0 1\n";
  REQUIRE(Read(dir.Write("faces_first.ply", ply), &mesh, &error) == Status::kOk);
  REQUIRE(mesh.triangles.size() == 1);
  CHECK(mesh.vertices[1] == Vec3{1, 0, 0});
  CHECK(Dot(TriangleCross(mesh, 0), Vec3{0, 1, 0}) == Approx(1));
}

TEST_CASE("ReadMesh: faces counts the file's polygons, skipped_faces those left out",
          "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  // Two good triangles, one collinear, two repeating a vertex.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 2 0 0\nv 0 0 1\nf 1 5 3\nf 1 3 2\nf 1 2 4\nf 1 1 2\nf 2 2 2\n";
  REQUIRE(Read(dir.Write("counts.obj", obj), &mesh, &error, &report) == Status::kOk);
  CHECK(report.faces == 5);
  CHECK(report.skipped_faces == 3);
  CHECK(mesh.triangles.size() == 2);
  CHECK(SurfaceArea(mesh) == Approx(1));
  // A quad with one collinear fan triangle is used, not skipped.
  REQUIRE(Read(dir.Write("quad.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 1 0 1\nf 1 4 3 2\n"), &mesh,
               &error, &report) == Status::kOk);
  CHECK(report.faces == 1);
  CHECK(report.skipped_faces == 0);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: an ASCII PLY record with a value too many is refused at its line",
          "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string vertices = "0 0 0\n1 0 0\n1 0 1\n0 0 1\n";
  REQUIRE(Read(dir.Write("ok.ply", header + vertices + "3 0 2 1\n3 0 3 2\n"), &mesh, &error) ==
          Status::kOk);
  CHECK(Read(dir.Write("face.ply", header + vertices + "3 0 2 1 3\n3 0 3 2\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "face.ply:14: expected 4 values for face 1: vertex_indices (its count, 3, and "
                 "3 items); found 5"));
  CHECK(Read(dir.Write("vertex.ply", header + "0 0 0\n1 0 0 7\n1 0 1\n0 0 1\n3 0 2 1\n3 0 3 2\n"),
             &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "vertex.ply:11: expected 3 values for vertex 2: x y z; found 4"));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: OBJ indices out of range are refused however negative", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  for (const std::string index : {"-5", "-4294967295", "-9223372036854775807",
                                  "-9223372036854775808", "-99999999999999999999"}) {
    INFO(index);
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1 0 1\nf 1 3 2\nf 2 3 " + index + "\n";
    CHECK(Read(dir.Write("far.obj", obj), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "far.obj:6: face uses vertex " + index +
                              " but only 4 vertices are defined before it"));
  }
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: messages show control bytes of the file as '?'", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  auto has_control = [](const std::string& text) {
    return std::any_of(text.begin(), text.end(),
                       [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
  };
  CHECK(Read(dir.Write("a.off", "OFF\033]0;title\007\n"), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "a.off:1: expected the header 'OFF', found 'OFF?]0;title?'"));
  CHECK_FALSE(has_control(error));
  CHECK(Read(dir.Write("a.obj", "v 0 0 0\nv 1 \033[2J 0\nv 0 0 1\nf 1 3 2\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "a.obj:2: vertex coordinate '?[2J' (bytes 1B 5B 32 4A) is not a finite number"));
  CHECK_FALSE(has_control(error));
  CHECK(Read(dir.Write("f.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 \0332\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "f.obj:4: face vertex '?2' is not a vertex index"));
  CHECK_FALSE(has_control(error));
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 0 1\n3 0 1 \0332\n";
  CHECK(Read(dir.Write("a.ply", ply), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "a.ply:13: face vertex '?2' is not an index below 3"));
  CHECK_FALSE(has_control(error));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: small faces far apart are kept", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  REQUIRE(Read(dir.Write("apart.obj",
                         "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 1e7 0 0\nv 10000001 0 0\nv 1e7 0 1\n"
                         "f 1 3 2\nf 4 6 5\n"),
               &mesh, &error, &report) == Status::kOk);
  CHECK(report.skipped_faces == 0);
  CHECK(SurfaceArea(mesh) == Approx(1));
  REQUIRE(Read(dir.Write("pebble.obj",
                         "v 0 0 0\nv 100000 0 0\nv 0 0 100000\nv 5 1 5\nv 5.01 1 5\nv 5 1 5.01\n"
                         "f 1 3 2\nf 4 6 5\n"),
               &mesh, &error, &report) == Status::kOk);
  CHECK(report.skipped_faces == 0);
  CHECK(mesh.triangles.size() == 2);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: a face listed twice is read once", "[import][mesh]") {
  // Listed again the other way round, it doubled the area and, turned to match, half the
  // samples faced down; in a larger mesh its edges made the mesh non-manifold.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  const std::string obj = "v 0 0 0\nv 0 0 1\nv 1 0 0\nv 1 0 1\nf 1 2 3\nf 3 2 4\nf 3 2 1\n";
  REQUIRE(Read(dir.Write("twice.obj", obj), &mesh, &error, &report) == Status::kOk);
  CHECK(report.faces == 3);
  CHECK(report.skipped_faces == 1);
  CHECK(SurfaceArea(mesh) == Approx(1));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) CHECK(TriangleCross(mesh, t).y > 0);
  // Corners at the same position count as the same (a soup's face listed again).
  const std::string soup =
      "v 0 0 0\nv 0 0 1\nv 1 0 0\nv 1 0 0\nv 0 0 1\nv 0 0 0\nf 1 2 3\nf 4 5 6\n";
  REQUIRE(Read(dir.Write("soup_twice.obj", soup), &mesh, &error, &report) == Status::kOk);
  CHECK(report.skipped_faces == 1);
  CHECK(SurfaceArea(mesh) == Approx(0.5));
}

TEST_CASE("ReadMesh: a concave polygon covers only itself", "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string obj =
      "v 2 0 1\nv 1 0 1\nv 1 0 2\nv 0 0 2\nv 0 0 0\nv 2 0 0\nf 1 2 3 4 5 6\n";  // an L facing -y
  REQUIRE(Read(dir.Write("L.obj", obj), &mesh, &error) == Status::kOk);
  CHECK(SurfaceArea(mesh) == Approx(3));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) CHECK(TriangleCross(mesh, t).y < 0);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: a face wound against its neighbours is turned to match them",
          "[import][mesh]") {
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  // A 10 x 10 quad floor facing +y, its face 56 wound the other way.
  const int n = 10;
  std::string obj;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) obj += "v " + std::to_string(i) + " 0 " + std::to_string(j) + "\n";
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j + 1;
      int f[4] = {a, a + 1, a + n + 2, a + n + 1};
      if (i * n + j == 55) std::reverse(f, f + 4);
      obj += "f " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
             " " + std::to_string(f[3]) + "\n";
    }
  }
  REQUIRE(Read(dir.Write("one_flipped.obj", obj), &mesh, &error, &report) == Status::kOk);
  CHECK(report.faces == 100);
  CHECK(report.turned_faces == 1);
  CHECK(report.skipped_faces == 0);
  CHECK(SurfaceArea(mesh) == Approx(100));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) CHECK(TriangleCross(mesh, t).y > 0);
  // The cube, wound consistently, turns none.
  REQUIRE(Read(dir.Write("cube.obj", kCubeObj), &mesh, &error, &report) == Status::kOk);
  CHECK(report.turned_faces == 0);
  // The same floor as a soup, each quad with its own copies of its corners (as split normals or
  // texture seams export it): its faces meet where their corners coincide.
  std::string soup;
  int corners = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      int x[4] = {i, i, i + 1, i + 1}, z[4] = {j, j + 1, j + 1, j};
      if (i * n + j == 55) std::reverse(x, x + 4), std::reverse(z, z + 4);
      for (int k = 0; k < 4; ++k)
        soup += "v " + std::to_string(x[k]) + " 0 " + std::to_string(z[k]) + "\n";
      soup += "f " + std::to_string(corners + 1) + " " + std::to_string(corners + 2) + " " +
              std::to_string(corners + 3) + " " + std::to_string(corners + 4) + "\n";
      corners += 4;
    }
  }
  REQUIRE(Read(dir.Write("soup.obj", soup), &mesh, &error, &report) == Status::kOk);
  CHECK(report.vertices == 400);
  CHECK(report.turned_faces == 1);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) CHECK(TriangleCross(mesh, t).y > 0);
}

TEST_CASE("ReadMesh: binary PLY list counts and vertex indices are whole numbers",
          "[import][mesh]") {
  // A float count of 3.5 read four indices (the next face's count among them), and a float
  // index of 1.5 was taken as vertex 1, silently.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  auto ply = [](const char* count_type, const char* index_type, float count, float index) {
    std::string s = std::string(
                        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float "
                        "x\nproperty float y\nproperty float z\nelement face 1\nproperty list ") +
                    count_type + " " + index_type + " vertex_indices\nend_header\n";
    const float v[9] = {0, 0, 0, 1, 0, 0, 1, 0, 1};
    s.append(reinterpret_cast<const char*>(v), sizeof v);
    s.append(reinterpret_cast<const char*>(&count), 4);
    const float indices[3] = {0, index, 2};
    s.append(reinterpret_cast<const char*>(indices), sizeof indices);
    return s;
  };
  REQUIRE(Read(dir.Write("good.ply", ply("float", "float", 3, 1)), &mesh, &error) == Status::kOk);
  CHECK(mesh.triangles.size() == 1);
  CHECK(Read(dir.Write("count.ply", ply("float", "float", 3.5f, 1)), &mesh, &error) ==
        Status::kParseError);
  CHECK(
      Contains(error, "count.ply: face 1: list 'vertex_indices' count 3.5 is not a whole number"));
  CHECK(Read(dir.Write("index.ply", ply("float", "float", 3, 1.5f)), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "index.ply: face 1: vertex index 1.5 is not an index below 3"));
  // A face of no vertices, alone in its file, was refused as truncated data (the size check
  // counted three indices a face).
  std::string empty =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float v[9] = {0, 0, 0, 1, 0, 0, 1, 0, 1};
  empty.append(reinterpret_cast<const char*>(v), sizeof v);
  empty.push_back('\0');
  CHECK(Read(dir.Write("empty.ply", empty), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "empty.ply: face 1 has 0 vertices, expected 3 or more"));
}

TEST_CASE("ReadMesh: OBJ face corners are v or v/vt or v//vn or v/vt/vn", "[import][mesh]") {
  // A corner '1/x' or '1/2/3/4' (a damaged or misexported face) was read as vertex 1, silently.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string v = "v 0 0 0\nv 1 0 0\nv 1 0 1\nvt 0 0\nvn 0 1 0\n";
  for (const char* face : {"f 1 3 2\n", "f 1/1 3/1 2/1\n", "f 1//1 3//1 2//1\n",
                           "f 1/1/1 3/1/1 2/1/1\n", "f -3/-1/-1 -1/-1/-1 -2/-1/-1\n"}) {
    INFO(face);
    REQUIRE(Read(dir.Write("good.obj", v + face), &mesh, &error) == Status::kOk);
    CHECK(mesh.triangles.size() == 1);
  }
  for (const char* face : {"f 1/x 3 2\n", "f 1 3/1/1/1 2\n", "f 1 3 2/1.5\n", "f 1 3 2//n\n"}) {
    INFO(face);
    CHECK(Read(dir.Write("bad.obj", v + face), &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "bad.obj:6: face vertex '"));
    CHECK(Contains(error, "' is not v, v/vt, v//vn or v/vt/vn"));
  }
}

TEST_CASE("ReadMesh: binary PLY data after the declared elements is refused", "[import][mesh]") {
  // A header declaring one face of a file holding two loaded the first face only, silently.
  // A line end after the data (as some writers add) is still read.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  auto ply = [](int declared, int held, const std::string& tail) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float "
        "x\nproperty float y\nproperty float z\nelement face " +
        std::to_string(declared) + "\nproperty list uchar int vertex_indices\nend_header\n";
    const float v[12] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1};
    s.append(reinterpret_cast<const char*>(v), sizeof v);
    const int32_t faces[2][3] = {{0, 2, 1}, {0, 3, 2}};
    for (int f = 0; f < held; ++f) {
      s.push_back(3);
      s.append(reinterpret_cast<const char*>(faces[f]), sizeof faces[f]);
    }
    return s + tail;
  };
  REQUIRE(Read(dir.Write("whole.ply", ply(2, 2, "")), &mesh, &error) == Status::kOk);
  CHECK(mesh.triangles.size() == 2);
  REQUIRE(Read(dir.Write("newline.ply", ply(2, 2, "\r\n")), &mesh, &error) == Status::kOk);
  CHECK(mesh.triangles.size() == 2);
  CHECK(Read(dir.Write("more.ply", ply(1, 2, "")), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "more.ply: 13 bytes after the data the header declares"));
}

TEST_CASE("ReadMesh: PLY element counts too large to add up are refused as truncated",
          "[import][mesh]") {
  // Two counts near 2^63 added up to a negative number of records: a file of one record read
  // as "1 vertices but no faces".
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string header =
      "element vertex 9223372036854775807\nproperty float x\nproperty float y\nproperty float "
      "z\nelement face 9223372036854775807\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  CHECK(Read(dir.Write("a.ply", "ply\nformat ascii 1.0\n" + header + "0 0 0\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "a.ply: truncated: the header declares"));
  CHECK(Read(dir.Write("b.ply",
                       "ply\nformat binary_little_endian 1.0\n" + header + std::string(12, '\0')),
             &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "b.ply: truncated: the header's elements need at least"));
}

TEST_CASE("ReadMesh: an ASCII STL facet loop left open is refused at its line", "[import][mesh]") {
  // Such a facet was dropped, silently, and the rest of the mesh loaded as if whole.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string whole =
      "facet normal 0 1 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 1 0 0\nendloop\n"
      "endfacet\n";
  const std::string open =
      "facet normal 0 1 0\nouter loop\nvertex 1 0 0\nvertex 0 0 1\nvertex 1 0 1\nendfacet\n";
  REQUIRE(Read(dir.Write("good.stl", "solid s\n" + whole + "endsolid s\n"), &mesh, &error) ==
          Status::kOk);
  CHECK(mesh.triangles.size() == 1);
  CHECK(Read(dir.Write("open.stl", "solid s\n" + open + whole + "endsolid s\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "open.stl:7: 'endfacet' inside the facet loop opened on line 3"));
  CHECK(Read(dir.Write("last.stl", "solid s\n" + whole + "facet normal 0 1 0\nouter loop\n" +
                                       "vertex 1 0 0\nendsolid s\n"),
             &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "last.stl:12: 'endsolid' inside the facet loop opened on line 10"));
  CHECK(Read(dir.Write("loose.stl", "solid s\n" + whole + "vertex 5 0 0\nendsolid s\n"), &mesh,
             &error) == Status::kParseError);
  CHECK(Contains(error, "loose.stl:9: vertex outside a facet loop"));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: OBJ lines ending in a backslash continue on the next line", "[import][mesh]") {
  // The OBJ format's line continuation: "face vertex '\' is not v, v/vt, v//vn or v/vt/vn".
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  const std::string obj =
      "# made in C:\\models\\\nv 0 0 \\\n  0\nv 1 0 0\nv 1 0 1\r\nv 0 0 1\nf 1 \\\r\n4 \\\n3 2\n";
  REQUIRE(Read(dir.Write("joined.obj", obj), &mesh, &error, &report) == Status::kOk);
  CHECK(report.vertices == 4);
  CHECK(report.faces == 1);
  CHECK(mesh.vertices[0] == Vec3{0, 0, 0});
  CHECK(SurfaceArea(mesh) == Approx(1));
  // A continued line's errors are named at its first line.
  CHECK(Read(dir.Write("bad.obj", "v 0 0 0\nv 1 \\\n0 x\nv 0 1 0\nf 1 2 3\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "bad.obj:2: vertex coordinate 'x' is not a finite number"));
  CHECK(Read(dir.Write("last.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 \\\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "last.obj:4: the line ends in '\\' (continued on the next line), but the "
                 "file ends there"));
}

TEST_CASE("ReadMesh: Microsoft C's NaN and infinity are not finite numbers at their line",
          "[import][mesh]") {
  // '#' started a comment: "v 0 0 1.#QNAN" read as "v 0 0 1.", and "v 1.#INF 0 0" as a vertex of
  // one coordinate.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  for (const std::string token : {"1.#QNAN", "-1.#IND", "1.#INF", "-1.#INF00", "1.#SNAN0"}) {
    INFO(token);
    const std::string why =
        "'" + token + "' is not a finite number (Microsoft C's NaN or infinity)";
    CHECK(Read(dir.Write("q.obj", "v 0 0 0\nv 1 0 " + token + "\nv 0 1 0\nf 1 2 3\n"), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "q.obj:2: vertex coordinate " + why));
    CHECK(Read(dir.Write("q.off", "OFF\n3 1 0\n0 0 0\n" + token + " 0 0\n0 1 0\n3 0 1 2\n"), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "q.off:4: vertex coordinate " + why));
    CHECK(Read(dir.Write("q.ply",
                         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty "
                         "float y\nproperty float z\nelement face 1\nproperty list uchar int "
                         "vertex_indices\nend_header\n0 0 0\n1 " +
                             token + " 0\n0 1 0\n3 0 1 2\n"),
               &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "q.ply:11: vertex coordinate " + why));
    CHECK(
        Read(dir.Write("q.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex " +
                                    token + " 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"),
             &mesh, &error) == Status::kParseError);
    CHECK(Contains(error, "q.stl:5: vertex coordinate " + why));
  }
}

TEST_CASE("ReadMesh: PLY tristrips are read as triangle strips", "[import][mesh]") {
  // A 'tristrips' element was passed over: "4 vertices but no faces", or with faces beside it,
  // the strips left out silently.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  MeshReadReport report;
  // Two strips over a row of three unit squares in the y = 0 plane (a -1 restarts a strip), the
  // second one starting with two triangles of a repeated corner (as strips stitched into one are
  // written), which are left out.
  const std::string header =
      "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  const float v[24] = {0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1, 2, 0, 0, 2, 0, 1, 3, 0, 0, 3, 0, 1};
  const int32_t strip[] = {0, 2, 1, 3, 4, 5, -1, 4, 4, 4, 5, 6, 7};
  std::string ascii = "ply\nformat ascii 1.0\n" + header + "0 0 0\n1 0 0\n0 0 1\n1 0 1\n" +
                      "2 0 0\n2 0 1\n3 0 0\n3 0 1\n13";
  for (int32_t i : strip) ascii += " " + std::to_string(i);
  std::string binary = "ply\nformat binary_little_endian 1.0\n" + header;
  binary.append(reinterpret_cast<const char*>(v), sizeof v);
  const int32_t n = 13;
  binary.append(reinterpret_cast<const char*>(&n), 4);
  binary.append(reinterpret_cast<const char*>(strip), sizeof strip);
  for (const auto& [name, text] :
       {std::make_pair("a.ply", ascii + "\n"), std::make_pair("b.ply", binary)}) {
    INFO(name);
    REQUIRE(Read(dir.Write(name, text), &mesh, &error, &report) == Status::kOk);
    CHECK(report.faces == 6);
    CHECK(report.skipped_faces == 0);
    CHECK(report.turned_faces == 0);  // every other triangle of a strip wound the other way
    CHECK(mesh.triangles.size() == 6);
    CHECK(SurfaceArea(mesh) == Approx(3));
    for (size_t t = 0; t < mesh.triangles.size(); ++t)  // one winding, turned up or down
      CHECK(std::fabs(Dot(Normalize(TriangleCross(mesh, t)), Vec3{0, 1, 0})) == Approx(1));
  }
  // Indices in a strip are -1 or vertices.
  std::string bad = ascii;
  bad.replace(bad.rfind(" 7"), 2, " 8");
  CHECK(Read(dir.Write("bad.ply", bad + "\n"), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "bad.ply:18: tristrips vertex '8' is not -1 or an index below 8"));
}

TEST_CASE("ReadMesh: a PLY element line needs a whole count", "[import][mesh]") {
  // "element vertex" without a count was passed over: its properties went to the element
  // before it, or were dropped.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string rest =
      "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  REQUIRE(Read(dir.Write("m.ply", "ply\nformat ascii 1.0\nelement vertex 3" + rest), &mesh,
               &error) == Status::kOk);
  for (const std::string count : {"", "-3", "3.0", "three"}) {
    INFO(count);
    CHECK(Read(dir.Write("m.ply", "ply\nformat ascii 1.0\nelement vertex " + count + rest), &mesh,
               &error) == Status::kParseError);
    CHECK(Contains(error, "m.ply:3: element 'vertex' " +
                              (count.empty() ? "has no count"
                                             : "count '" + count + "' is not a whole number >= 0") +
                              " (expected 'element NAME COUNT')"));
  }
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: PLY header lines that are not read are refused at their line",
          "[import][mesh]") {
  // Each was passed over: a misspelt keyword, a property without its name or before any
  // element, a property or element given twice (the last x read), a face element without an
  // index list ("4 vertices but no faces", or the faces left out beside other ones).
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string vertex =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string data = "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::pair<std::string, std::string> cases[] = {
      {"elemnt vertex 3\n" + vertex + face,
       "m.ply:3: 'elemnt' does not start a PLY header line (expected format, element, "
       "property, comment, obj_info or end_header)"},
      {"property float w\n" + vertex + face,
       "m.ply:3: a property before any element (expected 'element NAME COUNT' before it)"},
      {vertex + "property float\n" + face, "m.ply:7: expected 'property TYPE NAME'"},
      {vertex + "property list uchar int\n" + face,
       "m.ply:7: expected 'property list COUNT_TYPE ITEM_TYPE NAME'"},
      {vertex + "property float x\n" + face,
       "m.ply:7: vertex property 'x' given again (first on line 4)"},
      {vertex + face + "element vertex 0\n",
       "m.ply:9: element 'vertex' given again (first on line 3)"},
      {vertex + "element face 1\nproperty list uchar int indices\n",
       "m.ply:7: element 'face' has no list property 'vertex_indices' (or 'vertex_index'): its 1 "
       "records cannot be read"},
  };
  for (const auto& [header, expected] : cases) {
    INFO(header);
    CHECK(Read(dir.Write("m.ply", "ply\nformat ascii 1.0\n" + header + data), &mesh, &error) ==
          Status::kParseError);
    CHECK(error == dir.File("m.ply") + expected.substr(5));
  }
  REQUIRE(Read(dir.Write("m.ply", "ply\nformat ascii 1.0\n" + vertex + face + data), &mesh,
               &error) == Status::kOk);
}

TEST_CASE("ReadMesh: ASCII PLY values of properties not read are numbers", "[import][mesh]") {
  // A damaged normal or colour ("abc") loaded without a word.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  auto ply = [](const std::string& nx) {
    return "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nproperty float nx\nelement face 1\nproperty list uchar int "
           "vertex_indices\nproperty list uchar float texcoord\nend_header\n0 0 0 0\n1 0 0 " +
           nx + "\n0 1 0 0\n3 0 1 2 2 0.5 " + nx + "\n";
  };
  for (const std::string nx : {"0.5", "nan", "-1.#IND", "1e999"})
    CHECK(Read(dir.Write("n.ply", ply(nx)), &mesh, &error) == Status::kOk);
  CHECK(Read(dir.Write("n.ply", ply("abc")), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "n.ply:13: vertex property 'nx': 'abc' is not a number"));
}

TEST_CASE("ReadMesh: OBJ statements of other kinds are named when no faces are read",
          "[import][mesh]") {
  // "V 0 0 0" lines read as "no vertices: the mesh is empty"; "fo", the faces of older files,
  // as "4 vertices but no faces"; a free-form surface was left out silently.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string v = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n";
  REQUIRE(Read(dir.Write("fo.obj", v + "fo 1 4 3 2\n"), &mesh, &error) == Status::kOk);
  CHECK(SurfaceArea(mesh) == Approx(1));
  CHECK(Read(dir.Write("up.obj", "V 0 0 0\nV 1 0 0\nV 0 1 0\nF 1 2 3\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "up.obj:1: 'V' is not an OBJ statement, and the file has no vertices "
                 "(expected 'v x y z' and 'f v1 v2 v3 ...', in lower case)"));
  CHECK(Read(dir.Write("face.obj", v + "# faces\nface 1 2 3\n"), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error, "face.obj:6: 'face' is not an OBJ statement, and the file has no faces"));
  CHECK(Read(dir.Write("surf.obj", v + "f 1 4 3 2\ncstype bezier\ndeg 1 1\nsurf 0 1 0 1 1 2 3 4\n"),
             &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "surf.obj:8: free-form surfaces ('surf') are not read"));
}

}  // namespace footfall

namespace footfall {

TEST_CASE("ReadMesh: ASCII STL lines of other kinds are refused at their line", "[import][mesh]") {
  // A damaged line ("foo bar") and a vertex of four coordinates were read past.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  auto stl = [](const std::string& vertex, const std::string& extra) {
    return "solid s\nfacet normal 0 1 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\n" + vertex +
           "\nendloop\nendfacet\n" + extra + "endsolid s\n";
  };
  REQUIRE(Read(dir.Write("s.stl", stl("vertex 1 0 0", "")), &mesh, &error) == Status::kOk);
  CHECK(Read(dir.Write("s.stl", stl("vertex 1 0 0", "foo bar\n")), &mesh, &error) ==
        Status::kParseError);
  CHECK(Contains(error,
                 "s.stl:9: 'foo' does not start an ASCII STL line (expected solid, facet "
                 "normal, outer loop, vertex, endloop, endfacet or endsolid)"));
  CHECK(Read(dir.Write("s.stl", stl("vertex 1 0 0 0", "")), &mesh, &error) == Status::kParseError);
  CHECK(Contains(error, "s.stl:6: vertex has 4 coordinates, expected 3"));
}

}  // namespace footfall
