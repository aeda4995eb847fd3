// Quaternion to Euler angle conversion for DCC tools that key rotations as Euler angles (Maya).
#pragma once

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
// so keyed rotations do not spin the long way round between keys.
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
// so keyed rotations do not spin the long way round between keys.
Vec3 ClosestEulerZxyDegrees(const Vec3& euler, const Vec3& previous);

}  // namespace footfall
