#include "footfall/import/triangle_mesh.h"

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

}  // namespace footfall
