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

// Checks that counts match, every value is finite and no normal is zero, then normalises the
// normals. On failure returns kInvalidArgument and names the first bad sample in *error.
Status ValidateAndNormalize(RawSamples* samples, std::string* error);

}  // namespace footfall
