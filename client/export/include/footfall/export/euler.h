// Quaternion to Euler angle conversion for DCC tools that key rotations as Euler angles (Maya).
#pragma once

#include <vector>

#include "footfall/steps/walk.h"
#include "footfall/terrain/vec3.h"

namespace footfall {

// Euler angles in degrees for Maya's default rotate order XYZ: rotating by x about the X axis,
// then y about Y, then z about Z (all about the parent's axes) gives the rotation of `q`.
// `q` need not be unit length but must be non-zero. y is in [-90, 90]; x and z in [-180, 180].
// At gimbal lock (y = +-90) x is 0.
Vec3 QuatToEulerXyzDegrees(const Quat& q);

// The Euler triple equivalent to `euler` (degrees, XYZ order) that is closest to `previous`:
// adds multiples of 360 per angle and also tries the alternative solution (x+180, 180-y, z+180),
// so keyed rotations do not spin the long way round between keys. At gimbal lock (y = +-90)
// the turn is split between x and z as near `previous` as it goes.
Vec3 ClosestEulerXyzDegrees(const Vec3& euler, const Vec3& previous);

// Euler angles in degrees for Maya's rotate order ZXY: rotating by z about the Z axis, then x
// about X, then y about Y (all about the parent's axes; R = Ry(y) * Rx(x) * Rz(z) on column
// vectors) gives the rotation of `q`. With Y up, heading is y alone, and gimbal lock (x = +-90)
// needs the body pitched 90 degrees (facing straight up or down), which a walk never does.
// `q` need not be unit length but must be non-zero. x is in [-90, 90]; y and z in [-180, 180].
// At gimbal lock (x = +-90) z is 0 and the remaining turn is in y.
Vec3 QuatToEulerZxyDegrees(const Quat& q);

// The Euler triple equivalent to `euler` (degrees, ZXY order) that is closest to `previous`:
// adds multiples of 360 per angle and also tries the alternative solution (180-x, y+180, z+180),
// so keyed rotations do not spin the long way round between keys. At gimbal lock (x = +-90)
// the turn is split between z and y as near `previous` as it goes.
Vec3 ClosestEulerZxyDegrees(const Vec3& euler, const Vec3& previous);

// Keys' rotations as ZXY Euler degrees, each the triple closest to its neighbour's, so that
// Maya's per-angle interpolation between keys turns the short way: keys at gimbal lock before
// the first key that is not split their turn as that key does (a Z-up body facing +-Y, then
// turning, leaned up to 10 degrees between its keys when its first key had the turn all in y).
std::vector<Vec3> ContinuousEulerZxyDegrees(const std::vector<Quat>& rotations);

}  // namespace footfall
