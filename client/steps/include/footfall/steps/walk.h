// Walk: the keyframed result of the step generator, and the input of every exporter (JSON,
// glTF, MEL) and of the viewer. World space throughout; frames are animation frames at `fps`.
#pragma once

#include <string>
#include <vector>

#include "footfall/terrain/vec3.h"

namespace footfall {

// A rotation as a unit quaternion (x, y, z, w).
struct Quat {
  double x = 0, y = 0, z = 0, w = 1;
};

// Where a foot key sits in its step: lift-off, top of the swing arc, touch-down. Body keys
// have no phase.
enum class KeyPhase { kNone, kStart, kMid, kEnd };

struct WalkKey {
  double frame = 0;
  KeyPhase phase = KeyPhase::kNone;
  Vec3 position;         // world space
  Vec3 normal{0, 1, 0};  // feet: unit terrain normal at the key (mid: the averaged normal)
  Quat rotation;         // body: world orientation
};

enum class TrackKind { kFoot, kBody };

// The keys of one animated node: a foot IK target or a body.
struct WalkTrack {
  std::string name;       // foot name from the character file, or "body"
  std::string character;  // crowd runs: which character ("" for a single character)
  TrackKind kind = TrackKind::kFoot;
  std::vector<WalkKey> keys;  // ascending frames
};

struct Walk {
  double fps = 24;
  std::vector<WalkTrack> tracks;
  // Empty when every requested step was generated; otherwise why the walk stopped early (for
  // example at a cliff: the step and position). The keys up to that point are kept.
  std::string stopped;
};

const char* PhaseName(KeyPhase phase);  // "start", "mid", "end" or ""

}  // namespace footfall
