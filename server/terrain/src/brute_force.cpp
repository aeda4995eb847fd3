#include "footfall/terrain/brute_force.h"

#include <limits>

#include "query_math.h"

namespace footfall {

template <typename Accept>
Foothold BruteForce::Nearest(const double ideal[3], double limit2, const Accept& accept) const {
  const TerrainGrid& g = grid_;
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  double best_d2 = limit2;
  uint32_t best_index = kNone, best_slot = kNone, best_cell = 0;
  for (uint32_t cell = 0; g.count_ > 0 && cell < g.cells_; ++cell) {
    for (uint32_t s = g.cell_start_[cell]; s < g.cell_start_[cell + 1]; ++s) {
      float p[3];
      g.LocalPoint(cell, s, p);
      const double d2 = detail::Dist2(p, ideal);
      if (!accept(p, d2)) continue;
      if (detail::Better(d2, g.answers_[s].index, best_d2, best_index))
        best_d2 = d2, best_index = g.answers_[s].index, best_cell = cell, best_slot = s;
    }
  }
  if (best_slot != kNone) return g.MakeFoothold(best_cell, best_slot);
  Foothold none;
  none.status = Status::kNoFoothold;
  return none;
}

Foothold BruteForce::Snap(const Vec3& q) const {
  if (!IsFinite(q)) return Foothold{};  // kInvalidArgument
  const double* o = grid_.origin_;
  const double c[3] = {q.x - o[0], q.y - o[1], q.z - o[2]};
  if (!detail::InQueryRange(c)) return Foothold{};
  return Nearest(c, std::numeric_limits<double>::infinity(),
                 [](const float*, double) { return true; });
}

Foothold BruteForce::Next(const StepQuery& q, double tolerance) const {
  detail::NextFrame f;
  if (!detail::MakeNextFrame(grid_.origin_, q, tolerance, &f)) return Foothold{};
  return Nearest(f.ideal, f.radius2, [&f](const float* p, double d2) {
    return d2 <= f.radius2 && detail::Ahead(p, f);
  });
}

}  // namespace footfall
