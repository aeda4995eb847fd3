// A double-precision 3D vector for world-space points and directions.
#pragma once

#include <cmath>
#include <limits>

namespace footfall {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(const Vec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 operator*(double s, const Vec3& a) { return a * s; }
inline Vec3 operator/(const Vec3& a, double s) { return {a.x / s, a.y / s, a.z / s}; }
inline Vec3& operator+=(Vec3& a, const Vec3& b) { return a = a + b; }
inline Vec3& operator-=(Vec3& a, const Vec3& b) { return a = a - b; }
inline bool operator==(const Vec3& a, const Vec3& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}
inline bool operator!=(const Vec3& a, const Vec3& b) { return !(a == b); }
inline double Dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double Length2(const Vec3& a) { return Dot(a, a); }
inline double Length(const Vec3& a) { return std::sqrt(Dot(a, a)); }
inline double Distance2(const Vec3& a, const Vec3& b) { return Length2(a - b); }
inline double Distance(const Vec3& a, const Vec3& b) { return Length(a - b); }
// a / |a|; a must be non-zero and finite.
inline Vec3 Normalize(const Vec3& a) { return a / Length(a); }
inline bool IsFinite(const Vec3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
inline Vec3 Lerp(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * t; }
// a / |a| for any finite non-zero a, even with components near 1e300 whose squares overflow
// (a is first scaled by its largest |component|); {0, 0, 0} when a is zero or not finite.
inline Vec3 SafeNormalize(const Vec3& a) {
  if (!IsFinite(a)) return {};
  const double scale = std::fmax(std::fabs(a.x), std::fmax(std::fabs(a.y), std::fabs(a.z)));
  if (!(scale > 0)) return {};
  return Normalize(a / scale);
}

// SafeNormalize(a), but a itself when its length is already 1 to within rounding: a unit
// normal written exactly and read back (a converted point file, samples sent to footfalld)
// keeps every bit, where normalising it again moved some by one.
inline Vec3 UnitNormal(const Vec3& a) {
  if (IsFinite(a) && std::fabs(Length2(a) - 1) <= 4 * std::numeric_limits<double>::epsilon())
    return a;
  return SafeNormalize(a);
}

}  // namespace footfall
