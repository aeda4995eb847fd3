// Editable terrain samples: world-space points with normals, as parsed from a file or a mesh.
// The grid builder (grid.h) packs them into an immutable TerrainGrid.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "footfall/terrain/status.h"
#include "footfall/terrain/vec3.h"

namespace footfall {

struct RawSamples {
  std::vector<Vec3> points;   // world space [(x, y, z)]
  std::vector<Vec3> normals;  // same count as points; unit length after validation
  size_t size() const { return points.size(); }
  void clear() { points.clear(), normals.clear(); }
  void push_back(const Vec3& point, const Vec3& normal) {
    points.push_back(point), normals.push_back(normal);
  }
};

namespace terrain {

// The largest magnitude of a sample coordinate. [Units: wu] The grid stores each point as a
// float offset from the centre of the samples' box (grid_build.cpp): with every coordinate
// within +-1e38, offsets stay within +-1e38, below FLT_MAX (3.4e38), and the box's extent (at
// most 2e38) and squared distances stay finite in double. Beyond it, a point could become an
// infinite float and queries answer inf. (Queries themselves must lie within 1e15 of the grid's
// origin: detail::kMaxQueryDistance.)
constexpr double kMaxCoordinate = 1e38;

}  // namespace terrain

// Checks one sample: coordinates finite and within +-terrain::kMaxCoordinate, normal finite and
// non-zero (any finite length: see NormalizeSafely). On failure returns kInvalidArgument and says
// in *what what is wrong and what was expected.
Status CheckSample(const Vec3& point, const Vec3& normal, std::string* what);

// The unit vector along `v`, scaled by its largest component first so that no finite vector
// overflows or underflows on the way. False when `v` is zero or not finite.
bool NormalizeSafely(const Vec3& v, Vec3* unit);

// Checks that counts match and every sample passes CheckSample, then normalises the normals. On
// failure returns kInvalidArgument and names the first bad sample in *error ("sample 3: ...").
Status ValidateAndNormalize(RawSamples* samples, std::string* error);

}  // namespace footfall
