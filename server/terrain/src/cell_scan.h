// The nearest-sample scan of one grid cell, four samples at a time. A cell's samples are stored
// as a run of x, then y, then z (floats, local), so four consecutive samples load as one vector
// per axis. Distances are computed in double exactly as detail::Dist2 computes them (the same
// operations in the same order, no fused multiply-add), so answers stay bit-identical to the
// brute-force oracle.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>

namespace footfall {
namespace detail {

typedef float Float4 __attribute__((vector_size(16)));
typedef double Double4 __attribute__((vector_size(32)));

// Scans the `count` samples of a cell whose positions start at `xyz` (x[count], y[count],
// z[count]) and whose first slot is `first`, for one nearer to q than *best_d2, or as near with
// a lower source index (index_of(slot)). Reads up to 3 floats past the cell's z run: the
// positions array is padded for that.
//
// Each lane keeps its least distance and the first offset reaching it (no branch per group);
// the lanes are merged once per cell. Within a cell, slots ascend with source index, so the
// first offset at the cell's least distance is its lowest index there.
template <typename IndexOf>
inline void ScanCellNearest(const float* xyz, uint32_t first, uint32_t count, const double q[3],
                            const IndexOf& index_of, double* best_d2, uint32_t* best_slot) {
  if (count == 0) return;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Double4 qx = {q[0], q[0], q[0], q[0]};
  const Double4 qy = {q[1], q[1], q[1], q[1]};
  const Double4 qz = {q[2], q[2], q[2], q[2]};
  const Double4 lane = {0, 1, 2, 3};
  const Double4 inf = {kInf, kInf, kInf, kInf};
  Double4 least = inf;  // per lane
  Double4 at = lane;    // per lane: the offset of its first sample at `least`
  for (uint32_t i = 0; i < count; i += 4) {
    Float4 x, y, z;  // loaded from any address; widened exactly
    std::memcpy(&x, xyz + i, sizeof x);
    std::memcpy(&y, xyz + count + i, sizeof y);
    std::memcpy(&z, xyz + 2 * size_t{count} + i, sizeof z);
    const Double4 dx = __builtin_convertvector(x, Double4) - qx;
    const Double4 dy = __builtin_convertvector(y, Double4) - qy;
    const Double4 dz = __builtin_convertvector(z, Double4) - qz;
    Double4 d2 = dx * dx + dy * dy + dz * dz;
    const double left = static_cast<double>(count - i);
    d2 = lane < left ? d2 : inf;
    const auto nearer = d2 < least;
    least = nearer ? d2 : least;
    at = nearer ? lane + static_cast<double>(i) : at;
  }
  // No lane reached the best so far (most neighbour cells): nothing to merge.
  const double bound = *best_d2;
  const auto reached = least <= Double4{bound, bound, bound, bound};
  if (!(reached[0] | reached[1] | reached[2] | reached[3])) return;
  const Double4 half = __builtin_shufflevector(least, least, 2, 3, 0, 1);
  const Double4 pair = least < half ? least : half;
  const Double4 swap = __builtin_shufflevector(pair, pair, 1, 0, 3, 2);
  const Double4 all = pair < swap ? pair : swap;  // the cell's least distance, in every lane
  const double big = static_cast<double>(count);
  const Double4 first_at = least == all ? at : Double4{big, big, big, big};
  const Double4 at_half = __builtin_shufflevector(first_at, first_at, 2, 3, 0, 1);
  const Double4 at_pair = first_at < at_half ? first_at : at_half;
  const double offset = at_pair[0] < at_pair[1] ? at_pair[0] : at_pair[1];
  const uint32_t slot = first + static_cast<uint32_t>(offset);
  if (all[0] < *best_d2) {
    *best_d2 = all[0], *best_slot = slot;
  } else if (all[0] == *best_d2 && (*best_slot == std::numeric_limits<uint32_t>::max() ||
                                    index_of(slot) < index_of(*best_slot))) {
    // An exact tie with the best of another cell: the lower source index wins.
    *best_slot = slot;
  }
}

}  // namespace detail
}  // namespace footfall
