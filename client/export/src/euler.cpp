#include "footfall/export/euler.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "walk_prep.h"

namespace footfall {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = 180.0 / kPi;

// `angle` plus the multiple of 360 that brings it closest to `target` (degrees).
double Unwrap(double angle, double target) {
  return angle + 360.0 * std::round((target - angle) / 360.0);
}

Vec3 UnwrapAll(const Vec3& euler, const Vec3& target) {
  return {Unwrap(euler.x, target.x), Unwrap(euler.y, target.y), Unwrap(euler.z, target.z)};
}

double L1(const Vec3& a, const Vec3& b) {
  return std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.z - b.z);
}

// Whether a middle angle (degrees, as converted) is at gimbal lock, +-90.
bool AtLock(double middle) { return std::abs(std::abs(middle) - 90) < 1e-9; }

// At gimbal lock the first and last angles turn about one axis: in a cyclic order (XYZ, ZXY)
// with the middle angle +90, first + t and last + t give the same rotation for any t (with -90,
// first + t and last - t). Sets the (first, last) of that family nearest (first_to, last_to):
// t halfway between the shifts each would need alone.
void NearestAtLock(double middle, double* first, double* last, double first_to, double last_to) {
  const double s = middle > 0 ? 1 : -1;
  // The shifts taken within half a turn of each other: halfway along the shorter arc.
  const double to_first = first_to - *first;
  const double t = 0.5 * (to_first + Unwrap(s * (last_to - *last), to_first));
  *first += t, *last += s * t;
}

}  // namespace

Vec3 QuatToEulerXyzDegrees(const Quat& q_in) {
  const Quat q = Normalized(q_in);
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  // Rotation matrix entries (column vectors) needed for R = Rz(c) * Ry(b) * Rx(a).
  const double m00 = 1 - 2 * (y * y + z * z);
  const double m01 = 2 * (x * y - z * w);
  const double m10 = 2 * (x * y + z * w);
  const double m11 = 1 - 2 * (x * x + z * z);
  const double m20 = 2 * (x * z - y * w);
  const double m21 = 2 * (y * z + x * w);
  const double m22 = 1 - 2 * (x * x + y * y);
  const double sin_b = std::clamp(-m20, -1.0, 1.0);
  const double b = std::asin(sin_b);
  double a, c;
  if (std::abs(sin_b) > 1 - 1e-12) {
    // Gimbal lock: X and Z turn about the same axis; put it all in Z.
    a = 0;
    c = std::atan2(-m01, m11);
  } else {
    a = std::atan2(m21, m22);
    c = std::atan2(m10, m00);
  }
  return {a * kDegrees, b * kDegrees, c * kDegrees};
}

Vec3 ClosestEulerXyzDegrees(const Vec3& euler, const Vec3& previous) {
  if (AtLock(euler.y)) {  // X first, Z last
    Vec3 e = euler;
    NearestAtLock(e.y, &e.x, &e.z, previous.x, previous.z);
    return UnwrapAll(e, previous);
  }
  const Vec3 direct = UnwrapAll(euler, previous);
  const Vec3 alternative = UnwrapAll({euler.x + 180.0, 180.0 - euler.y, euler.z + 180.0}, previous);
  return L1(alternative, previous) < L1(direct, previous) ? alternative : direct;
}

Vec3 QuatToEulerZxyDegrees(const Quat& q_in) {
  const Quat q = Normalized(q_in);
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  // Rotation matrix entries (column vectors) needed for R = Ry(b) * Rx(a) * Rz(c):
  // m12 = -sin a; m02, m22 = sin b cos a, cos b cos a; m10, m11 = cos a sin c, cos a cos c.
  const double m00 = 1 - 2 * (y * y + z * z);
  const double m02 = 2 * (x * z + y * w);
  const double m10 = 2 * (x * y + z * w);
  const double m11 = 1 - 2 * (x * x + z * z);
  const double m12 = 2 * (y * z - x * w);
  const double m20 = 2 * (x * z - y * w);
  const double m22 = 1 - 2 * (x * x + y * y);
  const double sin_a = std::clamp(-m12, -1.0, 1.0);
  double a, b, c;
  if (std::abs(sin_a) > 1 - 1e-12) {
    // Gimbal lock: Z and Y turn about the same axis; put it all in Y (m00 = cos b,
    // m20 = -sin b with c = 0).
    a = std::copysign(kPi / 2, sin_a);
    b = std::atan2(-m20, m00);
    c = 0;
  } else {
    a = std::asin(sin_a);
    b = std::atan2(m02, m22);
    c = std::atan2(m10, m11);
  }
  return {a * kDegrees, b * kDegrees, c * kDegrees};
}

Vec3 ClosestEulerZxyDegrees(const Vec3& euler, const Vec3& previous) {
  if (AtLock(euler.x)) {  // Z first, Y last
    Vec3 e = euler;
    NearestAtLock(e.x, &e.z, &e.y, previous.z, previous.y);
    return UnwrapAll(e, previous);
  }
  const Vec3 direct = UnwrapAll(euler, previous);
  const Vec3 alternative = UnwrapAll({180.0 - euler.x, euler.y + 180.0, euler.z + 180.0}, previous);
  return L1(alternative, previous) < L1(direct, previous) ? alternative : direct;
}

std::vector<Vec3> ContinuousEulerZxyDegrees(const std::vector<Quat>& rotations) {
  std::vector<Vec3> out(rotations.size());
  for (size_t k = 0; k < rotations.size(); ++k) out[k] = QuatToEulerZxyDegrees(rotations[k]);
  // Keys at gimbal lock before the first that is not take its angles, nearest first: their
  // split of the turn between Z and Y is free, and all in Y swung the body between them and it.
  size_t first = 0;
  while (first < out.size() && AtLock(out[first].x)) ++first;
  if (first == out.size()) first = 0;
  for (size_t k = first; k-- > 0;) out[k] = ClosestEulerZxyDegrees(out[k], out[k + 1]);
  for (size_t k = first + 1; k < out.size(); ++k)
    out[k] = ClosestEulerZxyDegrees(out[k], out[k - 1]);
  return out;
}

}  // namespace footfall
