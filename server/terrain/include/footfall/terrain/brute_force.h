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
  const TerrainGrid& grid_;
};

}  // namespace footfall
