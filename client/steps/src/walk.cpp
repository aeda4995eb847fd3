#include "footfall/steps/walk.h"

#include <algorithm>
#include <cmath>

namespace footfall {

Quat Normalized(const Quat& q) {
  const double m = std::max({std::fabs(q.x), std::fabs(q.y), std::fabs(q.z), std::fabs(q.w)});
  if (!std::isfinite(m) || !(m > 0)) return Quat{};
  const Quat s{q.x / m, q.y / m, q.z / m, q.w / m};
  const double n = std::sqrt(s.x * s.x + s.y * s.y + s.z * s.z + s.w * s.w);
  return {s.x / n, s.y / n, s.z / n, s.w / n};
}

std::vector<size_t> KeyOrder(const WalkTrack& track) {
  const auto& keys = track.keys;
  std::vector<size_t> order;
  order.reserve(keys.size());
  for (size_t i = 0; i < keys.size(); ++i)
    if (std::isfinite(keys[i].frame)) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&keys](size_t a, size_t b) { return keys[a].frame < keys[b].frame; });
  std::vector<size_t> kept;
  kept.reserve(order.size());
  for (size_t index : order) {
    if (!kept.empty() && keys[kept.back()].frame == keys[index].frame)
      kept.back() = index;  // same frame: the later key wins
    else
      kept.push_back(index);
  }
  return kept;
}

const char* PhaseName(KeyPhase phase) {
  switch (phase) {
    case KeyPhase::kStart:
      return "start";
    case KeyPhase::kMid:
      return "mid";
    case KeyPhase::kEnd:
      return "end";
    case KeyPhase::kNone:
      break;
  }
  return "";
}

bool SwingStartsAt(const std::pmr::vector<WalkKey>& keys, size_t i) {
  if (i + 2 >= keys.size() || keys[i + 1].phase != KeyPhase::kMid ||
      keys[i + 2].phase != KeyPhase::kEnd)
    return false;
  return keys[i].phase == KeyPhase::kStart || keys[i].phase == KeyPhase::kEnd;
}

}  // namespace footfall
