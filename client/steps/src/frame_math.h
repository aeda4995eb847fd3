// Small vector and rotation helpers of the step generator. World space; angles in radians.
#pragma once

#include <algorithm>
#include <cmath>

#include "footfall/steps/walk.h"
#include "footfall/terrain/vec3.h"

namespace footfall::steps_detail {

constexpr double kPi = 3.14159265358979323846;
inline double Radians(double deg) { return deg * kPi / 180; }
inline double Degrees(double rad) { return rad * 180 / kPi; }

// v without its component along the unit normal n.
inline Vec3 ProjectOnPlane(const Vec3& v, const Vec3& n) { return v - n * Dot(v, n); }

// The ground straight above or below `start` along the unit `up`, from *found, the surface's
// point nearest `start`: `snap(q, &next)` finds the point nearest q (false: it failed), and
// is asked again at the line's point at the height of the last one found until that stays
// (a height field settles in two or three). True, with *found that ground, when it lies
// within `within` of the line; *found unchanged otherwise, and when it lies that near already.
// `point_of(found)` is its position.
template <typename Found, typename Snap, typename PointOf>
bool SettleAlongUp(const Vec3& start, const Vec3& up, double within, Found* found, Snap&& snap,
                   PointOf&& point_of) {
  auto across = [&](const Vec3& p) { return Length((p - start) - up * Dot(p - start, up)); };
  if (across(point_of(*found)) <= within) return false;
  Found ground = *found;
  constexpr int kMostSnaps = 8;
  for (int i = 0; i < kMostSnaps; ++i) {
    const Vec3 at = point_of(ground);
    Found next;
    if (!snap(start + up * Dot(at - start, up), &next) || point_of(next) == at) break;
    ground = next;
  }
  if (across(point_of(ground)) > within) return false;
  *found = ground;
  return true;
}

// v / |v|, or `fallback` when v is (nearly) zero.
inline Vec3 NormalizeOr(const Vec3& v, const Vec3& fallback) {
  const double len = Length(v);
  return len > 1e-12 ? v / len : fallback;
}

// The unit normal of the plane fitted to points[0..n), on the side of the unit vector `side`;
// `side` itself when the points lie (nearly) on a line or the plane leans more than 60 degrees
// from it. (The least-squares fit of the points' offsets along the axis the plane faces most,
// from the largest of the covariance's three 2 x 2 minors: the points' plane when they lie in
// one, else leaning toward that axis, so not quite the same for points turned about another.
// The orthogonal fit, the covariance's direction of least spread, changed walks on stairs: an
// octopod's hind foot then stopped at a riser's foot.)
inline Vec3 FittedPlaneNormal(const Vec3* points, size_t n, const Vec3& side) {
  if (n < 3) return side;
  Vec3 c;
  for (size_t i = 0; i < n; ++i) c += points[i];
  c = c / static_cast<double>(n);
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 d = points[i] - c;
    xx += d.x * d.x, xy += d.x * d.y, xz += d.x * d.z;
    yy += d.y * d.y, yz += d.y * d.z, zz += d.z * d.z;
  }
  const double det_x = yy * zz - yz * yz, det_y = xx * zz - xz * xz, det_z = xx * yy - xy * xy;
  const double det_max = std::max({det_x, det_y, det_z});
  const double spread = xx + yy + zz;
  if (!(det_max > 1e-6 * spread * spread)) return side;  // (nearly) collinear
  Vec3 normal;
  if (det_max == det_x) {
    normal = {det_x, xz * yz - xy * zz, xy * yz - xz * yy};
  } else if (det_max == det_y) {
    normal = {xz * yz - xy * zz, det_y, xy * xz - yz * xx};
  } else {
    normal = {xy * yz - xz * yy, xy * xz - yz * xx, det_z};
  }
  normal = Normalize(normal);
  if (Dot(normal, side) < 0) normal = normal * -1.0;
  return Dot(normal, side) >= 0.5 ? normal : side;
}

// Angle between two unit vectors.
inline double AngleBetween(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(Dot(a, b), -1.0, 1.0));
}

// A unit vector perpendicular to the unit vector n.
inline Vec3 AnyPerpendicular(const Vec3& n) {
  const Vec3 axis = std::fabs(n.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 0, 1};
  return Normalize(Cross(n, axis));
}

// v rotated by `angle` around the unit axis (right-handed).
inline Vec3 RotateAround(const Vec3& v, const Vec3& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + Cross(axis, v) * s + axis * (Dot(axis, v) * (1 - c));
}

// v carried by the smallest rotation that takes unit vector `from` to unit vector `to`.
inline Vec3 Transport(const Vec3& v, const Vec3& from, const Vec3& to) {
  const Vec3 axis = Cross(from, to);
  const double s = Length(axis), c = Dot(from, to);
  if (s < 1e-12) return c > 0 ? v : RotateAround(v, AnyPerpendicular(from), kPi);
  return RotateAround(v, axis / s, std::atan2(s, c));
}

// A unit forward direction in the plane of unit normal `up`: `want` projected onto it, or
// `previous` carried onto it when `want` is (nearly) along `up`.
inline Vec3 TangentForward(const Vec3& want, const Vec3& previous, const Vec3& previous_up,
                           const Vec3& up) {
  const Vec3 p = ProjectOnPlane(want, up);
  if (Length2(p) > 1e-8 * Length2(want)) return Normalize(p);
  const Vec3 carried = ProjectOnPlane(Transport(previous, previous_up, up), up);
  return NormalizeOr(carried, AnyPerpendicular(up));
}

// The rotation whose columns are the character axes in world space: X = left, Y = up,
// Z = forward (orthonormal, right-handed).
inline Quat QuatFromBasis(const Vec3& x, const Vec3& y, const Vec3& z) {
  const double m00 = x.x, m10 = x.y, m20 = x.z;
  const double m01 = y.x, m11 = y.y, m21 = y.z;
  const double m02 = z.x, m12 = z.y, m22 = z.z;
  Quat q;
  const double trace = m00 + m11 + m22;
  if (trace > 0) {
    const double s = 0.5 / std::sqrt(trace + 1);
    q.w = 0.25 / s, q.x = (m21 - m12) * s, q.y = (m02 - m20) * s, q.z = (m10 - m01) * s;
  } else if (m00 > m11 && m00 > m22) {
    const double s = 2 * std::sqrt(1 + m00 - m11 - m22);
    q.w = (m21 - m12) / s, q.x = 0.25 * s, q.y = (m01 + m10) / s, q.z = (m02 + m20) / s;
  } else if (m11 > m22) {
    const double s = 2 * std::sqrt(1 + m11 - m00 - m22);
    q.w = (m02 - m20) / s, q.x = (m01 + m10) / s, q.y = 0.25 * s, q.z = (m12 + m21) / s;
  } else {
    const double s = 2 * std::sqrt(1 + m22 - m00 - m11);
    q.w = (m10 - m01) / s, q.x = (m02 + m20) / s, q.y = (m12 + m21) / s, q.z = 0.25 * s;
  }
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  q.x /= n, q.y /= n, q.z /= n, q.w /= n;
  if (q.w < 0) q.x = -q.x, q.y = -q.y, q.z = -q.z, q.w = -q.w;  // one sign, for stable output
  return q;
}

}  // namespace footfall::steps_detail
