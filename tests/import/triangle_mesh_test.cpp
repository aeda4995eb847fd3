#include "footfall/import/triangle_mesh.h"

#include <cmath>
#include <memory>
#include <random>

#include "footfall/import/mesh_generators.h"
#include "test_support.h"

namespace footfall {

TEST_CASE("NearestSurfacePoint: on the mesh, as near as the nearest triangle", "[import][mesh]") {
  const TriangleMesh meshes[] = {MakeSphereMesh({1, 2, 3}, 2.0, 2), MakeRocksMesh(8, 0.5, 1.5, 3),
                                 MakeStairsMesh(4, 0.2, 0.3, 1.0)};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coord(-6, 6);
  for (const TriangleMesh& mesh : meshes) {
    for (int i = 0; i < 300; ++i) {
      const Vec3 q{coord(rng), coord(rng), coord(rng)};
      const Vec3 p = NearestSurfacePoint(mesh, q);
      CHECK(test::DistanceToMesh(mesh, p) < 1e-9);
      CHECK(Distance(p, q) == Approx(test::DistanceToMesh(mesh, q)).margin(1e-9));
    }
  }
  // Without triangles: the nearest vertex; without vertices: q itself.
  TriangleMesh points;
  points.vertices = {{0, 0, 0}, {5, 0, 0}};
  CHECK(NearestSurfacePoint(points, {4, 1, 0}) == Vec3{5, 0, 0});
  CHECK(NearestSurfacePoint(TriangleMesh{}, {4, 1, 0}) == Vec3{4, 1, 0});
}

TEST_CASE("CropToBox: keeps exactly the triangles meeting the box, and their vertices",
          "[import][mesh]") {
  const TriangleMesh mesh = MakeRocksMesh(20, 0.5, 1.5, 7);  // 10 x 10 in x and z
  const Vec3 lo{2.2, -10, 3.1}, hi{4.7, 10, 6.05};
  TriangleMesh cropped = mesh;
  const size_t removed = CropToBox(&cropped, lo, hi);
  // The oracle: every triangle tested on its own, in order.
  std::vector<std::array<Vec3, 3>> expected;
  for (const auto& tri : mesh.triangles) {
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    const bool meets = std::max({a.x, b.x, c.x}) >= lo.x && std::min({a.x, b.x, c.x}) <= hi.x &&
                       std::max({a.y, b.y, c.y}) >= lo.y && std::min({a.y, b.y, c.y}) <= hi.y &&
                       std::max({a.z, b.z, c.z}) >= lo.z && std::min({a.z, b.z, c.z}) <= hi.z;
    if (meets) expected.push_back({a, b, c});
  }
  REQUIRE(cropped.triangles.size() == expected.size());
  CHECK(removed == mesh.triangles.size() - expected.size());
  CHECK(expected.size() > 20);
  CHECK(removed > 20);
  std::vector<bool> used(cropped.vertices.size(), false);
  for (size_t t = 0; t < expected.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      REQUIRE(cropped.triangles[t][k] < cropped.vertices.size());
      CHECK(cropped.vertices[cropped.triangles[t][k]] == expected[t][k]);
      used[cropped.triangles[t][k]] = true;
    }
  }
  CHECK(std::count(used.begin(), used.end(), false) == 0);  // no vertex left unused
  // A box holding everything keeps everything.
  TriangleMesh whole = mesh;
  CHECK(CropToBox(&whole, {-100, -100, -100}, {100, 100, 100}) == 0);
  CHECK(whole.triangles.size() == mesh.triangles.size());
}

TEST_CASE("CornerNormals: smooth across gentle edges, sharp at creases", "[import][mesh]") {
  // Two unit squares folded along their shared edge (x from 0 to 1 at z = 0): one lies in the
  // floor (normal +y), the other rises by `fold` degrees; vertices shared, as modelled.
  constexpr double kPi = 3.14159265358979323846;
  for (const double fold : {20.0, 59.0, 61.0, 90.0}) {
    INFO("fold " << fold);
    const double a = fold * kPi / 180;
    TriangleMesh sheet;
    sheet.vertices = {{0, 0, -1},
                      {1, 0, -1},
                      {0, 0, 0},
                      {1, 0, 0},
                      {0, std::sin(a), std::cos(a)},
                      {1, std::sin(a), std::cos(a)}};
    sheet.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};
    const Vec3 floor{0, 1, 0}, rise{0, std::cos(a), -std::sin(a)};
    for (const double crease : {0.0, 60.0, 180.0}) {
      INFO("crease " << crease);
      const CornerNormals normals(sheet, crease);
      const bool smooth = fold <= crease;
      for (size_t t = 0; t < sheet.triangles.size(); ++t) {
        const Vec3 face = t < 2 ? floor : rise;
        const std::array<Vec3, 3> n = normals.Of(t);
        for (int k = 0; k < 3; ++k) {
          // Smooth: the area-weighted mean of every triangle at the vertex (each triangle is
          // half a unit square here); sharp: the face's own.
          const uint32_t v = sheet.triangles[t][k];
          Vec3 sum;
          for (size_t u = 0; u < sheet.triangles.size(); ++u) {
            const auto& tri = sheet.triangles[u];
            if (tri[0] == v || tri[1] == v || tri[2] == v) sum += u < 2 ? floor : rise;
          }
          const Vec3 want = smooth ? Normalize(sum) : face;
          CHECK(Distance(n[k], want) < 1e-12);
        }
      }
    }
  }
  // A degenerate triangle has no normal.
  TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  const std::array<Vec3, 3> none = CornerNormals(flat, 60).Of(0);
  for (const Vec3& n : none) CHECK(n == Vec3{});
}

TEST_CASE("TurnOutward: inside-out and downward meshes are turned over, others left alone",
          "[import][mesh]") {
  auto reversed = [](TriangleMesh m) {
    for (auto& tri : m.triangles) std::swap(tri[1], tri[2]);
    return m;
  };
  const Vec3 up{0, 1, 0};
  struct Case {
    TriangleMesh mesh;
    bool closed;
  };
  const Case cases[] = {{MakeSphereMesh({1, 2, 3}, 2.0, 2), true},
                        {MakeRocksMesh(8, 0.5, 1.5, 3), false},
                        {MakeStairsMesh(4, 0.2, 0.3, 1.0), false}};
  for (const Case& c : cases) {
    TriangleMesh as_is = c.mesh;
    const MeshTurnover kept = TurnOutward(&as_is, up);
    CHECK(kept.turned_faces == 0);
    CHECK(kept.closed_shells == (c.closed ? 1u : 0u));
    CHECK(as_is.triangles == c.mesh.triangles);
    TriangleMesh turned = reversed(c.mesh);
    const MeshTurnover t = TurnOutward(&turned, up);
    CHECK(t.turned_faces == c.mesh.triangles.size());
    CHECK(t.inside_out_shells == (c.closed ? 1u : 0u));
    CHECK(t.open_faced_down == !c.closed);
    for (size_t i = 0; i < turned.triangles.size(); ++i)
      CHECK(Distance(TriangleCross(turned, i), TriangleCross(c.mesh, i)) < 1e-12);
  }
  // Faces facing every way (a wall, facing +z or -z) and a terrain facing sideways (up is +y
  // but the rocks face +y: a Z-up caller) are left as they are.
  TriangleMesh wall;
  wall.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  wall.triangles = {{0, 1, 2}, {0, 2, 3}};
  for (const TriangleMesh& m : {wall, reversed(wall)}) {
    TriangleMesh w = m;
    CHECK(TurnOutward(&w, up).turned_faces == 0);
  }
  TriangleMesh rocks = reversed(MakeRocksMesh(8, 0.5, 1.5, 3));
  CHECK(TurnOutward(&rocks, Vec3{0, 0, 1}).turned_faces == 0);
}

TEST_CASE("TurnOutward: a closed soup, its corners split per face, is one closed shell",
          "[import][mesh]") {
  // Each triangle with its own copies of its corners (an STL-like soup, or a mesh exported with
  // split normals): taken vertex by vertex it has no closed part, and an inside-out one kept
  // its inward normals.
  TriangleMesh sphere = MakeSphereMesh({1, 2, 3}, 2.0, 2), soup;
  for (const auto& tri : sphere.triangles) {
    const uint32_t first = static_cast<uint32_t>(soup.vertices.size());
    for (uint32_t v : tri) soup.vertices.push_back(sphere.vertices[v]);
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  TriangleMesh as_is = soup;
  const MeshTurnover kept = TurnOutward(&as_is, {0, 1, 0});
  CHECK(kept.closed_shells == 1);
  CHECK(kept.turned_faces == 0);
  for (auto& tri : soup.triangles) std::swap(tri[1], tri[2]);
  const MeshTurnover t = TurnOutward(&soup, {0, 1, 0});
  CHECK(t.closed_shells == 1);
  CHECK(t.inside_out_shells == 1);
  CHECK(t.turned_faces == soup.triangles.size());
  for (size_t i = 0; i < soup.triangles.size(); ++i)
    CHECK(Distance(TriangleCross(soup, i), TriangleCross(as_is, i)) < 1e-12);
}

TEST_CASE("CoincidentVertexIds: the lowest index at each position", "[import][mesh]") {
  const std::vector<Vec3> v = {{1, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 0, -0.0}, {2, 0, 0}};
  CHECK(CoincidentVertexIds(v) == std::vector<uint32_t>{0, 1, 0, 1, 4});
  CHECK(CoincidentVertexIds({}).empty());
}

TEST_CASE("TurnOutward: a shell closed but for a T-junction is closed", "[import][mesh]") {
  // A unit cube whose top has a corner at the middle of its front edge, which the front face
  // does not have: the zero-area triangle ear clipping leaves at a concave face's straight
  // corner. Taken for an open part, an inside-out staircase of concave end faces was not
  // turned over, and insects walked inside it.
  TriangleMesh cube;
  cube.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},  {0, 0, 1},
                   {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0.5, 0, 1}};
  cube.triangles = {{0, 3, 2}, {0, 2, 1}, {4, 8, 7}, {8, 6, 7}, {8, 5, 6}, {0, 1, 5}, {0, 5, 4},
                    {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  TriangleMesh as_is = cube;
  const MeshTurnover kept = TurnOutward(&as_is, {0, 1, 0});
  CHECK(kept.closed_shells == 1);
  CHECK(kept.turned_faces == 0);
  for (auto& tri : cube.triangles) std::swap(tri[1], tri[2]);
  const MeshTurnover t = TurnOutward(&cube, {0, 1, 0});
  CHECK(t.closed_shells == 1);
  CHECK(t.inside_out_shells == 1);
  CHECK(t.turned_faces == cube.triangles.size());
  // The corner 1e-7 off the edge (coordinates written with six decimals put a modelled corner
  // that far off): still a T-junction.
  TriangleMesh rounded = as_is;
  rounded.vertices[8].y += 1e-7;
  CHECK(TurnOutward(&rounded, {0, 1, 0}).closed_shells == 1);
  // A real opening stays open: the top without its middle triangle.
  TriangleMesh holed = as_is;
  holed.triangles.erase(holed.triangles.begin() + 3);
  CHECK(TurnOutward(&holed, {0, 1, 0}).closed_shells == 0);
}

TEST_CASE("TurnOutward: each closed shell is judged on its own", "[import][mesh]") {
  // An inside-out sphere and a smaller one wound right, in one mesh (and open ground beside
  // them, facing up): only the inside-out shell is turned (the whole mesh's volume, negative,
  // turned both).
  const TriangleMesh big = MakeSphereMesh({0, 3, 0}, 2.0, 2);
  const TriangleMesh small = MakeSphereMesh({6, 1, 0}, 0.5, 2);
  const TriangleMesh ground = MakeRocksMesh(6, 0.5, 0.3, 2);
  TriangleMesh mesh;
  auto append = [&](const TriangleMesh& part, bool flip) {
    const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
    for (auto tri : part.triangles) {
      if (flip) std::swap(tri[1], tri[2]);
      mesh.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
    }
  };
  append(big, true), append(small, false), append(ground, false);
  const TriangleMesh before = mesh;
  const MeshTurnover t = TurnOutward(&mesh, {0, 1, 0});
  CHECK(t.closed_shells == 2);
  CHECK(t.inside_out_shells == 1);
  CHECK_FALSE(t.open_faced_down);
  CHECK(t.open_faces == ground.triangles.size());
  CHECK(t.turned_faces == big.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const bool in_big = i < big.triangles.size();
    CHECK((mesh.triangles[i] == before.triangles[i]) == !in_big);
  }
}

TEST_CASE("TurnOutward: shells that touch, each with its own vertices, are judged apart",
          "[import][mesh]") {
  // Axis-aligned boxes of 12 triangles, wound outward, each with its own eight vertices.
  auto box = [](const Vec3& lo, const Vec3& hi) {
    TriangleMesh m;
    for (int i = 0; i < 8; ++i)
      m.vertices.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads) {
      m.triangles.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
      m.triangles.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
    }
    return m;
  };
  REQUIRE(TurnOutward(std::make_unique<TriangleMesh>(box({0, 0, 0}, {1, 1, 1})).get(), {0, 1, 0})
              .inside_out_shells == 0);
  TriangleMesh ground;  // a 6 x 6 sheet facing up, its middle corner under the boxes' corner
  ground.vertices = {{-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}, {0, 0, 0}};
  ground.triangles = {{4, 1, 0}, {4, 2, 1}, {4, 3, 2}, {4, 0, 3}};
  struct Part {
    TriangleMesh mesh;
    bool flip;
  };
  // A large inside-out box resting on a small right one at a corner (their volumes summed,
  // both were turned); an inside-out box on the ground at that corner (taken for part of the
  // open ground, it was left inside out).
  const std::vector<std::vector<Part>> scenes = {
      {{box({0, 0, 0}, {1, 1, 1}), false}, {box({1, 1, 1}, {4, 4, 4}), true}},
      {{ground, false}, {box({0, 0, 0}, {1, 1, 1}), true}},
      {{ground, false}, {box({0, 0, 0}, {1, 1, 1}), false}, {box({-1, 0, -1}, {0, 2, 0}), true}}};
  for (size_t s = 0; s < scenes.size(); ++s) {
    INFO("scene " << s);
    TriangleMesh mesh;
    std::vector<bool> flipped;
    for (const Part& part : scenes[s]) {
      const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
      mesh.vertices.insert(mesh.vertices.end(), part.mesh.vertices.begin(),
                           part.mesh.vertices.end());
      for (auto tri : part.mesh.triangles) {
        if (part.flip) std::swap(tri[1], tri[2]);
        mesh.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
        flipped.push_back(part.flip);
      }
    }
    const TriangleMesh before = mesh;
    const MeshTurnover t = TurnOutward(&mesh, {0, 1, 0});
    CHECK(t.inside_out_shells == 1);
    CHECK_FALSE(t.open_faced_down);
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
      CHECK((mesh.triangles[i] != before.triangles[i]) == flipped[i]);
  }
}

TEST_CASE("CornerNormals: a soup is smoothed as the mesh it models", "[import][mesh]") {
  // The same rocks with shared vertices and as a soup (each triangle its own corners, as an
  // OBJ exported split at seams has them): the same corner normals at every crease angle.
  const TriangleMesh mesh = MakeRocksMesh(8, 0.5, 1.5, 3);
  TriangleMesh soup;
  for (const auto& tri : mesh.triangles) {
    const uint32_t first = static_cast<uint32_t>(soup.vertices.size());
    for (uint32_t v : tri) soup.vertices.push_back(mesh.vertices[v]);
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  size_t smoothed = 0;
  for (const double crease : {30.0, 60.0, 180.0}) {
    const CornerNormals shared(mesh, crease), split(soup, crease);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const std::array<Vec3, 3> a = shared.Of(t), b = split.Of(t);
      const Vec3 face = Normalize(TriangleCross(mesh, t));
      for (int k = 0; k < 3; ++k) {
        CHECK(Distance(a[k], b[k]) < 1e-12);
        smoothed += Distance(b[k], face) > 1e-3;
      }
    }
  }
  CHECK(smoothed > mesh.triangles.size());  // not every corner kept its face's normal
}

}  // namespace footfall

namespace footfall {

TEST_CASE("IsDegenerateTriangle: judged on the triangle's own size and position",
          "[import][mesh]") {
  // Real triangles, whatever the rest of a mesh: a 1 m triangle 1e7 from the origin, a 1 cm one
  // near it, a 1e-6 one at the origin.
  CHECK_FALSE(IsDegenerateTriangle({1e7, 0, 0}, {1e7, 0, 1}, {1e7 + 1, 0, 0}));
  CHECK_FALSE(IsDegenerateTriangle({5, 1, 5}, {5, 1, 5.01}, {5.01, 1, 5}));
  CHECK_FALSE(IsDegenerateTriangle({0, 0, 0}, {0, 0, 1e-6}, {1e-6, 0, 0}));
  // Zero area: collinear (exactly, or within the rounding of the coordinates), a repeated
  // point, a needle 1e14 long and 1 wide.
  CHECK(IsDegenerateTriangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0}));
  CHECK(IsDegenerateTriangle({0, 0, 0}, {0.1, 0, 0.1}, {0.3, 0, 0.3}));
  CHECK(IsDegenerateTriangle({1e7, 0, 0}, {1e7 + 0.1, 0, 1e-12}, {1e7 + 0.2, 0, 0}));
  CHECK(IsDegenerateTriangle({1, 2, 3}, {1, 2, 3}, {4, 5, 6}));
  CHECK(IsDegenerateTriangle({0, 1e14, 0}, {1, 0, 0}, {0, 0, 1}));
  // RemoveDegenerateTriangles keeps a pebble beside a 100 km ground triangle.
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1e5, 0, 0}, {0, 0, 1e5}, {5, 1, 5}, {5.01, 1, 5}, {5, 1, 5.01}};
  mesh.triangles = {{0, 2, 1}, {3, 5, 4}};
  CHECK(RemoveDegenerateTriangles(&mesh) == 0);
  CHECK(mesh.triangles.size() == 2);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("TriangulatePolygon: ear clipping in the polygon's plane, a fan when convex",
          "[import][mesh]") {
  using Triangles = std::vector<std::array<uint32_t, 3>>;
  auto area = [](const std::vector<Vec3>& v, const Triangles& t, Vec3 up) {
    double sum = 0;
    for (const auto& tri : t)
      sum += 0.5 * Dot(Cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]]), up);
    return sum;
  };
  SECTION("a convex polygon gives the fan of its first corner") {
    const std::vector<Vec3> v = {{0, 0, 0}, {0, 0, 1}, {1, 0, 2}, {2, 0, 1}, {2, 0, 0}};
    Triangles t;
    CHECK(TriangulatePolygon(v, {0, 1, 2, 3, 4}, &t));
    CHECK(t == Triangles{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}});
  }
  SECTION("an L-shaped floor is cut along its inside, every piece facing as it does") {
    // (2,0,1) (1,0,1) (1,0,2) (0,0,2) (0,0,0) (2,0,0), facing -y: the notch is x, z in (1, 2).
    const std::vector<Vec3> v = {{2, 0, 1}, {1, 0, 1}, {1, 0, 2}, {0, 0, 2}, {0, 0, 0}, {2, 0, 0}};
    Triangles t;
    CHECK(TriangulatePolygon(v, {0, 1, 2, 3, 4, 5}, &t));
    REQUIRE(t.size() == 4);
    for (const auto& tri : t) {
      const Vec3 n = Cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]]);
      CHECK(n.y < 0);
      const Vec3 centre = (v[tri[0]] + v[tri[1]] + v[tri[2]]) / 3;
      CHECK_FALSE((centre.x > 1 && centre.z > 1));
    }
    CHECK(area(v, t, {0, -1, 0}) == Approx(3));
  }
  SECTION("a tilted concave polygon, in its own plane") {
    // A star of 10 corners around the axis (1, 1, 1).
    const Vec3 u = Normalize(Vec3{1, -1, 0}), w = Normalize(Cross(Vec3{1, 1, 1}, u));
    std::vector<Vec3> v;
    std::vector<uint32_t> corners;
    for (int i = 0; i < 10; ++i) {
      const double r = i % 2 ? 0.4 : 1.0, a = i * 3.14159265358979 / 5;
      v.push_back(Vec3{5, 6, 7} + u * (r * std::cos(a)) + w * (r * std::sin(a)));
      corners.push_back(static_cast<uint32_t>(i));
    }
    Triangles t;
    CHECK(TriangulatePolygon(v, corners, &t));
    CHECK(t.size() == 8);
    // The star's area: 10 triangles between the centre and its edges.
    double star = 0;
    for (int i = 0; i < 10; ++i)
      star += 0.5 * Length(Cross(v[i] - Vec3{5, 6, 7}, v[(i + 1) % 10] - Vec3{5, 6, 7}));
    CHECK(area(v, t, Normalize(Cross(u, w))) == Approx(star));
  }
  SECTION("a self-intersecting polygon falls back to a fan") {
    const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 1}, {1, 0, 0}, {0, 0, 1}};  // a bow tie
    Triangles t;
    CHECK_FALSE(TriangulatePolygon(v, {0, 1, 2, 3}, &t));
    CHECK(t == Triangles{{0, 1, 2}, {0, 2, 3}});
    const std::vector<Vec3> skewed = {{0, 0, 0}, {1, 0, 1}, {1.2, 0, 0}, {0, 0, 1}};
    Triangles u;
    TriangulatePolygon(skewed, {0, 1, 2, 3}, &u);
    CHECK(u.size() == 2);
  }
  SECTION("a non-convex polygon of thousands of corners is cut along its inside") {
    // Zigzags of 600 to 8,000 corners, fanned when over 256: the fan covered the notches
    // outside and held triangles facing the other way (a floor sampled half facing down).
    for (const size_t teeth : {300u, 1000u, 4000u}) {
      std::vector<Vec3> v;
      std::vector<uint32_t> corners;
      for (size_t i = 0; i < teeth; ++i) v.push_back({double(i), 0, i % 2 ? 1.0 : 0.5});
      for (size_t i = teeth; i-- > 0;) v.push_back({double(i), 0, -1});
      for (uint32_t i = 0; i < v.size(); ++i) corners.push_back(i);
      Triangles t;
      INFO(teeth << " teeth");
      CHECK(TriangulatePolygon(v, corners, &t));
      CHECK(t.size() == v.size() - 2);
      double shoelace = 0;  // the polygon's area, facing -y as its corners run
      for (size_t i = 0; i < v.size(); ++i) {
        const Vec3 &p = v[i], &q = v[(i + 1) % v.size()];
        shoelace += 0.5 * (p.z * q.x - p.x * q.z);
      }
      const Vec3 facing{0, shoelace > 0 ? 1.0 : -1.0, 0};
      size_t against = 0;
      for (const auto& tri : t)
        against += !(Dot(Cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]]), facing) > 0);
      CHECK(against == 0);
      CHECK(area(v, t, facing) == Approx(std::fabs(shoelace)));
    }
  }
  SECTION("large polygons: convex ones in linear time, non-convex ones past the limit fanned") {
    // A 200,000-corner circle (ear clipping took seconds at 16,000), and a zigzag of
    // 2 * kMaxClippedCorners corners (minutes at a few thousand).
    std::vector<Vec3> v;
    std::vector<uint32_t> corners;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      const double a = -2 * 3.141592653589793 * i / n;
      v.push_back({std::cos(a), 0, std::sin(a)});
      corners.push_back(static_cast<uint32_t>(i));
    }
    Triangles t;
    CHECK(TriangulatePolygon(v, corners, &t));
    CHECK(t.size() == n - 2u);
    v.clear(), corners.clear();
    const size_t teeth = kMaxClippedCorners;
    for (size_t i = 0; i < teeth; ++i) v.push_back({double(i), 0, i % 2 ? 1.0 : 0.5});
    for (size_t i = teeth; i-- > 0;) v.push_back({double(i), 0, -1});
    for (uint32_t i = 0; i < v.size(); ++i) corners.push_back(i);
    Triangles z;
    CHECK_FALSE(TriangulatePolygon(v, corners, &z));
    CHECK(z.size() == v.size() - 2);
  }
}

}  // namespace footfall
