// Walk: the keyframed result of the step generator, and the input of every exporter (JSON,
// glTF, MEL) and of the viewer. World space throughout; frames are animation frames at `fps`.
#pragma once

#include <cstdint>
#include <memory>
#include <memory_resource>
#include <string>
#include <vector>

#include "footfall/terrain/vec3.h"

namespace footfall {

// A rotation as a unit quaternion (x, y, z, w).
struct Quat {
  double x = 0, y = 0, z = 0, w = 1;
};

// v rotated by the unit quaternion q.
inline Vec3 Rotate(const Quat& q, const Vec3& v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = Cross(u, v) * 2;
  return v + t * q.w + Cross(u, t);
}

// q / |q| (scaled by its largest component first, so that no square overflows or
// underflows); the identity when q is zero or not finite.
Quat Normalized(const Quat& q);

// Where a foot key sits in its step: lift-off, top of the swing arc, touch-down. Body keys
// have no phase.
enum class KeyPhase : uint8_t { kNone, kStart, kMid, kEnd };

// One key of a track: 64 bytes, as a crowd's walk holds millions of them. A body's orientation
// is kept beside its keys (WalkTrack::rotations).
struct WalkKey {
  double frame = 0;
  Vec3 position;         // world space
  Vec3 normal{0, 1, 0};  // feet: unit terrain normal at the key (mid: the averaged normal);
                         // body: its up
  KeyPhase phase = KeyPhase::kNone;
};
static_assert(sizeof(WalkKey) == 64, "WalkKey is one cache line's worth");

enum class TrackKind { kFoot, kBody };

// Keeps alive the memory resource a track's keys were allocated from, exactly as long as the
// keys are: it follows the keys as std::pmr::vector's allocator does. Moving a track moves it
// along; a copy of a track (whose keys go to the default heap) holds none; assigning to a track
// keeps the track's own (its keys stay where they were allocated).
class KeyMemory {
 public:
  KeyMemory() = default;
  explicit KeyMemory(std::shared_ptr<std::pmr::memory_resource> resource)
      : resource_(std::move(resource)) {}
  KeyMemory(const KeyMemory&) {}
  KeyMemory(KeyMemory&&) noexcept = default;
  KeyMemory& operator=(const KeyMemory&) { return *this; }
  KeyMemory& operator=(KeyMemory&&) noexcept { return *this; }
  // The resource, or nullptr for the default heap.
  std::pmr::memory_resource* get() const { return resource_.get(); }

 private:
  std::shared_ptr<std::pmr::memory_resource> resource_;
};

// The keys of one animated node: a foot IK target or a body.
struct WalkTrack {
  std::string name;       // foot name from the character file, or "body"
  std::string character;  // crowd runs: which character ("" for a single character)
  TrackKind kind = TrackKind::kFoot;
  // Where keys and rotations live when it is not the default heap: the step generator puts a
  // walk's keys in one block it shares between the tracks (a crowd's walk holds millions of
  // keys). The track holds it, so a track outlives its walk safely; copies of the keys use the
  // default heap. Declared before the keys: destroyed after them.
  KeyMemory memory;
  std::pmr::vector<WalkKey> keys;  // ascending frames
  // Body tracks: the body's world orientation at each key (rotations[i] at keys[i]). Foot
  // tracks: empty, or each key's orientation once given (AddFootRotations, foot_rotations.h).
  std::pmr::vector<Quat> rotations;
  // Foot tracks: the length of the foot's sole (its character's foot_length), for drawing it;
  // 0 for point feet, for body tracks, and when not known. [Units: wu]
  double foot_length = 0;
  // Foot tracks: the width of the foot's sole (its character's foot_width), for drawing it; 0
  // for none, for body tracks, and when not known. [Units: wu]
  double foot_width = 0;

  // The orientation at keys[i]: rotations[i], or the identity where there is none.
  Quat Rotation(size_t i) const { return i < rotations.size() ? rotations[i] : Quat{}; }
};

struct Walk {
  double fps = 24;
  // The linear unit of the walk's lengths, as linear_units.h names them ("cm"), when it is known;
  // "" when it is not (one walk unit is then one unit of wherever it goes). The glTF export
  // converts a walk with a unit to metres, the MEL export keys it in that unit, and the walk
  // JSON carries it.
  std::string unit;
  std::vector<WalkTrack> tracks;
  // Empty when every requested step was generated; otherwise why the walk stopped early (for
  // example at a cliff: the step and position). The keys up to that point are kept. A crowd's
  // names its earliest stop and counts the others.
  std::string stopped;
  // Every stopped character's reason, earliest step first (not written to files: the walk JSON
  // carries `stopped` alone).
  std::vector<std::string> stops;
  // What is worth saying of a walk, one line each (not written to files either): first what
  // the set-up found (a start given farther than a step from the terrain, and where the
  // character starts instead; a step_length longer than the reach lets a foot travel, and the
  // step taken instead), then, one line per character, earliest first, a path walk given its
  // number of steps that did them all short of its goal: how far the goal still is.
  std::vector<std::string> notes;
  // True when the walk stopped because the serving engine failed (footfalld died or stopped
  // answering after the first step), not at the terrain: stopped and stops then begin with
  // that failure (not written to files).
  bool session_failed = false;
  // How many of stops, from the front, are the engine's failures (one per character it failed).
  size_t failed_stops = 0;
};

// Indices into track.keys in ascending frame order (stable); of keys sharing a frame only the
// last (in track order) is listed. Keys whose frame is not finite are left out.
std::vector<size_t> KeyOrder(const WalkTrack& track);

const char* PhaseName(KeyPhase phase);  // "start", "mid", "end" or ""

// Whether keys[i] of a foot track starts a swing (keys[i + 1] its mid key, keys[i + 2] its
// touch-down): a start key, or an end key followed by a mid key (a foot that lifts on the frame
// it lands, in a gait of one group).
bool SwingStartsAt(const std::pmr::vector<WalkKey>& keys, size_t i);

}  // namespace footfall
