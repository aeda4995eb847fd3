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

}  // namespace footfall
