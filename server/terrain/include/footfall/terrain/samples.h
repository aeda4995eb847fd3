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

// The largest |x|, |y| or |z| a terrain sample may have. [Units: wu] The grid stores samples as
// float offsets from its origin, a point inside the samples' bounds, and refuses queries farther
// than 1e15 from that origin (kMaxQueryDistance, query_math.h), where squared distances in double
// can no longer tell samples apart. Within +-5e14 every sample is at most 1e15 from any origin
// inside the bounds, so every sample stays reachable by a query (float offsets, which overflow
// near 3.4e38, are far from their limit). Terrain readers refuse larger coordinates at load.
constexpr double kMaxCoordinate = 5e14;

}  // namespace terrain

// Checks one sample: coordinates finite and within +-terrain::kMaxCoordinate, normal finite and
// non-zero (any finite length: see SafeNormalize in vec3.h). On failure returns kInvalidArgument
// and says in *what what is wrong and what was expected.
Status CheckSample(const Vec3& point, const Vec3& normal, std::string* what);

// Checks that counts match and every sample passes CheckSample, then normalises the normals. On
// failure returns kInvalidArgument and names the first bad sample in *error ("sample 3: ...").
Status ValidateAndNormalize(RawSamples* samples, std::string* error);

}  // namespace footfall
