#include "footfall/steps/walk.h"

namespace footfall {

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
