// Helpers shared by the import tests: temporary files, brute-force geometry oracles, and the
// location of the shared real data.
#pragma once

#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/import/triangle_mesh.h"

namespace footfall::test {

// A fresh directory under the system temp dir, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  std::string File(const std::string& name) const { return path_ + "/" + name; }
  // Writes `content` to name and returns its path.
  std::string Write(const std::string& name, const std::string& content) const;

 private:
  std::string path_;
};

// Distance from p to triangle (a, b, c). [Units: wu]
double PointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Distance from p to the nearest triangle of `mesh`, and that triangle's index.
double DistanceToMesh(const TriangleMesh& mesh, const Vec3& p, size_t* triangle = nullptr);

// The shared data directory (CMAKE_SOURCE_DIR/../shared/data/terrain) or "" when it is absent
// outside CI; inside CI its absence fails the calling test.
std::string SharedTerrainDir();

}  // namespace footfall::test
