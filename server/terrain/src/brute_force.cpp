#include "footfall/terrain/brute_force.h"

#include <limits>

#include "query_math.h"

namespace footfall {

Foothold BruteForce::Snap(const Vec3& q) const {
  Foothold none;
  if (!IsFinite(q)) return none;
  const TerrainGrid& g = grid_;
  const double c[3] = {q.x - g.origin_[0], q.y - g.origin_[1], q.z - g.origin_[2]};
  if (!detail::InQueryRange(c)) return none;
  none.status = Status::kNoFoothold;
  double best_d2 = std::numeric_limits<double>::infinity();
  uint32_t best_index = std::numeric_limits<uint32_t>::max(), best_slot = best_index;
  uint32_t best_cell = 0;
  for (uint32_t cell = 0; g.count_ > 0 && cell < g.cells_; ++cell) {
    for (uint32_t s = g.cell_start_[cell]; s < g.cell_start_[cell + 1]; ++s) {
      float p[3];
      g.LocalPoint(cell, s, p);
      const double d2 = detail::Dist2(p, c);
      if (detail::Better(d2, g.answers_[s].index, best_d2, best_index))
        best_d2 = d2, best_index = g.answers_[s].index, best_cell = cell, best_slot = s;
    }
  }
  return best_slot == std::numeric_limits<uint32_t>::max() ? none
                                                           : g.MakeFoothold(best_cell, best_slot);
}

Foothold BruteForce::Next(const StepQuery& q, double tolerance) const {
  Foothold none;
  const TerrainGrid& g = grid_;
  detail::NextFrame f;
  if (!detail::MakeNextFrame(g.origin_, q, tolerance, &f)) return none;
  none.status = Status::kNoFoothold;
  double best_d2 = f.radius2;
  uint32_t best_index = std::numeric_limits<uint32_t>::max(), best_slot = best_index;
  uint32_t best_cell = 0;
  for (uint32_t cell = 0; g.count_ > 0 && cell < g.cells_; ++cell) {
    for (uint32_t s = g.cell_start_[cell]; s < g.cell_start_[cell + 1]; ++s) {
      float p[3];
      g.LocalPoint(cell, s, p);
      const double d2 = detail::Dist2(p, f.ideal);
      if (d2 > f.radius2 || !detail::Ahead(p, f)) continue;
      if (detail::Better(d2, g.answers_[s].index, best_d2, best_index))
        best_d2 = d2, best_index = g.answers_[s].index, best_cell = cell, best_slot = s;
    }
  }
  return best_slot == std::numeric_limits<uint32_t>::max() ? none
                                                           : g.MakeFoothold(best_cell, best_slot);
}

}  // namespace footfall
