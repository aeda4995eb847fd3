// The axis the view stands on: the world's up, turned onto render space's +y (the camera's
// up), so a Z-up terrain (a GIS height map) is seen standing, not on its side. Only the six
// axis directions: they turn axis-aligned boxes (grid cells, bounds) into axis-aligned boxes,
// and coordinates exactly (a swap and a sign), so a turned scene draws the same floats.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "footfall/terrain/vec3.h"

namespace footfall::viewer {

struct ViewUp {
  int axis = 1;  // 0 x, 1 y, 2 z
  int sign = 1;  // +1 or -1
  bool operator==(const ViewUp& o) const { return axis == o.axis && sign == o.sign; }
};

// Reads "x", "y", "z", "-x", "-y", "-z" (either case) or a vector "DX,DY,DZ" along one of
// them (as `footfall generate --up` takes it: "0,0,1"). Returns false, with the problem in
// *error, for anything else.
bool ParseViewUp(const std::string& text, ViewUp* up, std::string* error);

// The up as a world-space unit vector.
Vec3 UpVector(const ViewUp& up);

// The proper rotation taking the world's up onto +y: render = rotation * world. Each row has
// a single +-1, so it moves coordinates without rounding.
glm::dmat3 RenderRotation(const ViewUp& up);

}  // namespace footfall::viewer
