// Arithmetic shared by TerrainGrid and BruteForce, so both compute bit-identical distances and
// predicates. Everything is in the grid's local frame (world minus origin), in double.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "footfall/terrain/grid.h"

namespace footfall {
namespace detail {

// Squared distance from a stored (float, local) point to a local query point.
inline double Dist2(const float* p, const double q[3]) {
  const double dx = static_cast<double>(p[0]) - q[0];
  const double dy = static_cast<double>(p[1]) - q[1];
  const double dz = static_cast<double>(p[2]) - q[2];
  return dx * dx + dy * dy + dz * dz;
}

// True when (d2, index) beats the best so far: nearer, or as near with a lower index.
inline bool Better(double d2, uint32_t index, double best_d2, uint32_t best_index) {
  return d2 < best_d2 || (d2 == best_d2 && index < best_index);
}

// Queries farther than this from the grid's origin are refused: there, squared distances keep
// no precision to tell samples apart. [Units: wu]
constexpr double kMaxQueryDistance = 1e15;
static_assert(
    2 * terrain::kMaxCoordinate <= kMaxQueryDistance,
    "a sample at +-kMaxCoordinate must be within query range of any origin in the bounds");

// True when a local query point is within kMaxQueryDistance of the origin along every axis.
inline bool InQueryRange(const double c[3]) {
  return std::fabs(c[0]) <= kMaxQueryDistance && std::fabs(c[1]) <= kMaxQueryDistance &&
         std::fabs(c[2]) <= kMaxQueryDistance;
}

// A next query in local coordinates.
struct NextFrame {
  double foot[3];
  double dir[3];
  double ideal[3];
  double radius2;
};

// Fills `frame` from a world-space query; false if the query is invalid (zero or non-finite
// direction, non-finite foot or tolerance).
inline bool MakeNextFrame(const double origin[3], const StepQuery& q, double tolerance,
                          NextFrame* frame) {
  if (!IsFinite(q.foot) || !IsFinite(q.direction) || !std::isfinite(tolerance)) return false;
  // Any non-zero direction is valid, also one whose squared length underflows (1e-170): its
  // candidate radius is then the tolerance, or (without one) the ideal point alone.
  if (q.direction.x == 0 && q.direction.y == 0 && q.direction.z == 0) return false;
  const double len2 = Length2(q.direction);
  const double foot[3] = {q.foot.x, q.foot.y, q.foot.z};
  const double dir[3] = {q.direction.x, q.direction.y, q.direction.z};
  for (int a = 0; a < 3; ++a) {
    frame->foot[a] = foot[a] - origin[a];
    frame->dir[a] = dir[a];
    frame->ideal[a] = frame->foot[a] + dir[a];
  }
  // A tolerance beyond any distance within query range reaches every sample as it is: squaring
  // it must not overflow (above 1e154 every query came back invalid).
  const double reach = std::min(tolerance, 4 * kMaxQueryDistance);
  frame->radius2 = tolerance > 0 ? reach * reach : len2;
  return std::isfinite(frame->radius2) && InQueryRange(frame->foot) && InQueryRange(frame->ideal);
}

// True when a stored point is strictly ahead of the foot: dot(p - foot, dir) > 0.
inline bool Ahead(const float* p, const NextFrame& f) {
  const double ax = static_cast<double>(p[0]) - f.foot[0];
  const double ay = static_cast<double>(p[1]) - f.foot[1];
  const double az = static_cast<double>(p[2]) - f.foot[2];
  return ax * f.dir[0] + ay * f.dir[1] + az * f.dir[2] > 0;
}

}  // namespace detail
}  // namespace footfall
