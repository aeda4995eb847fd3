// BruteForce: the oracle for TerrainGrid. It scans every stored sample of a grid with the same
// arithmetic as the grid's queries, so its answers must equal the grid's exactly.
#pragma once

#include "footfall/terrain/grid.h"

namespace footfall {

class BruteForce {
 public:
  explicit BruteForce(const TerrainGrid& grid) : grid_(grid) {}
  Foothold Snap(const Vec3& q) const;
  Foothold Next(const StepQuery& q, double tolerance) const;

 private:
  // The sample nearest the local point `ideal` among those accept(p, d2) keeps, within limit2
  // (ties: lowest index), or kNoFoothold.
  template <typename Accept>
  Foothold Nearest(const double ideal[3], double limit2, const Accept& accept) const;

  const TerrainGrid& grid_;
};

}  // namespace footfall
