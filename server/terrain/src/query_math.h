// Arithmetic shared by TerrainGrid and BruteForce, so both compute bit-identical distances and
// predicates. Distances are in the grid's local frame (world minus origin), in double; the
// ahead test is on the world points answers report.
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

// A next query: its ideal point in local coordinates, its foot in world coordinates (see Ahead).
struct NextFrame {
  double origin[3];  // the grid's
  double foot[3];    // world
  double dir[3];
  double ideal[3];  // local
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
  double local_foot[3];
  for (int a = 0; a < 3; ++a) {
    frame->origin[a] = origin[a];
    frame->foot[a] = foot[a];
    frame->dir[a] = dir[a];
    local_foot[a] = foot[a] - origin[a];
    frame->ideal[a] = local_foot[a] + dir[a];
  }
  // A tolerance beyond any distance within query range reaches every sample as it is: squaring
  // it must not overflow (above 1e154 every query came back invalid).
  const double reach = std::min(tolerance, 4 * kMaxQueryDistance);
  frame->radius2 = tolerance > 0 ? reach * reach : len2;
  return std::isfinite(frame->radius2) && InQueryRange(local_foot) && InQueryRange(frame->ideal);
}

// dot(w - foot, dir) for the world point w = origin + p that an answer at local point p
// reports, computed as a caller checks it: no answer is level with or behind the foot by the
// caller's arithmetic. Non-decreasing in each coordinate of p along the sign of dir (rounding
// is monotonic), so a box's corner farthest along dir bounds every point inside it.
inline double AheadBy(const double p[3], const NextFrame& f) {
  const double ax = (f.origin[0] + p[0]) - f.foot[0];
  const double ay = (f.origin[1] + p[1]) - f.foot[1];
  const double az = (f.origin[2] + p[2]) - f.foot[2];
  return ax * f.dir[0] + ay * f.dir[1] + az * f.dir[2];
}

// True when a stored (float, local) point is strictly ahead of the foot (AheadBy > 0).
inline bool Ahead(const float* p, const NextFrame& f) {
  const double d[3] = {p[0], p[1], p[2]};
  return AheadBy(d, f) > 0;
}

}  // namespace detail
}  // namespace footfall
