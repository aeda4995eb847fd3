#include "test_support.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace footfall::test {

TempDir::TempDir() {
  std::string pattern =
      (std::filesystem::temp_directory_path() / "footfall-import-XXXXXX").string();
  REQUIRE(mkdtemp(&pattern[0]) != nullptr);
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::string TempDir::Write(const std::string& name, const std::string& content) const {
  const std::string path = File(name);
  std::ofstream out(path, std::ios::binary);
  out << content;
  REQUIRE(out.good());
  return path;
}

double PointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection 5.1.5: the closest point by Voronoi regions.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = Dot(ab, ap), d2 = Dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return Distance(p, a);
  const Vec3 bp = p - b;
  const double d3 = Dot(ab, bp), d4 = Dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return Distance(p, b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return Distance(p, a + ab * (d1 / (d1 - d3)));
  const Vec3 cp = p - c;
  const double d5 = Dot(ab, cp), d6 = Dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return Distance(p, c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return Distance(p, a + ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return Distance(p, b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  }
  const double denom = 1 / (va + vb + vc);
  return Distance(p, a + ab * (vb * denom) + ac * (vc * denom));
}

double DistanceToMesh(const TriangleMesh& mesh, const Vec3& p, size_t* triangle) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const double d = PointTriangleDistance(p, mesh.vertices[tri[0]], mesh.vertices[tri[1]],
                                           mesh.vertices[tri[2]]);
    if (d < best) {
      best = d;
      if (triangle) *triangle = t;
    }
  }
  return best;
}

std::string SharedTerrainDir() {
  const std::string dir = FOOTFALL_SHARED_DATA "/terrain";
  if (std::filesystem::exists(dir + "/terrain_kootenai_1m_50x37.asc")) return dir;
  if (std::getenv("CI")) {
    FAIL("shared data missing in CI: " << dir);
  }
  WARN("skipped: shared data not found at " << dir << " (CI is unset)");
  return "";
}

}  // namespace footfall::test
