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
template <typename IndexOf>
inline void ScanCellNearest(const float* xyz, uint32_t first, uint32_t count, const double q[3],
                            const IndexOf& index_of, double* best_d2, uint32_t* best_slot) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Double4 qx = {q[0], q[0], q[0], q[0]};
  const Double4 qy = {q[1], q[1], q[1], q[1]};
  const Double4 qz = {q[2], q[2], q[2], q[2]};
  const Double4 lane = {0, 1, 2, 3};
  const Double4 inf = {kInf, kInf, kInf, kInf};
  const Double4 four = {4, 4, 4, 4};
  double best = *best_d2;
  uint32_t slot = *best_slot;
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
    const Double4 half = __builtin_shufflevector(d2, d2, 2, 3, 0, 1);
    const Double4 pair_min = d2 < half ? d2 : half;
    const Double4 swap = __builtin_shufflevector(pair_min, pair_min, 1, 0, 3, 2);
    const Double4 all_min = pair_min < swap ? pair_min : swap;
    if (all_min[0] < best) {
      // The first lane holding the minimum: within a cell, slots ascend with source index.
      const Double4 at = d2 == all_min ? lane : four;
      const Double4 at_half = __builtin_shufflevector(at, at, 2, 3, 0, 1);
      const Double4 at_pair = at < at_half ? at : at_half;
      const double first_lane = at_pair[0] < at_pair[1] ? at_pair[0] : at_pair[1];
      best = all_min[0], slot = first + i + static_cast<uint32_t>(first_lane);
    } else if (all_min[0] == best) {
      // An exact tie with the best so far (another cell's, or an earlier group's): the lower
      // source index wins.
      const uint32_t lanes = count - i < 4 ? count - i : 4;
      for (uint32_t l = 0; l < lanes; ++l) {
        const uint32_t s = first + i + l;
        if (d2[l] == best &&
            (slot == std::numeric_limits<uint32_t>::max() || index_of(s) < index_of(slot)))
          slot = s;
      }
    }
  }
  *best_d2 = best;
  *best_slot = slot;
}

}  // namespace detail
}  // namespace footfall
