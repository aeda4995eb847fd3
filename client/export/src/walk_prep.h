// Preparing a walk for export, shared by the glTF and MEL writers: input checks, the order in
// which a track's keys are written, and unique node names.
#pragma once

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall {
namespace walk_export {

// Sets *error to `message` when error is non-null.
void SetError(std::string* error, const std::string& message);

// kOk when fps is finite and > 0 and every key has a finite frame and position, and every body
// key a finite, non-zero quaternion; otherwise kInvalidArgument with the track and key named.
Status CheckWalk(const Walk& walk, std::string* error);

// Indices into track.keys in ascending frame order (stable); of keys sharing a frame only the
// last (in track order) is listed.
std::vector<size_t> KeyOrder(const WalkTrack& track);

// "name" for a single character, "character/name" for a crowd track; "track<i>" when the track
// has no name.
std::string QualifiedTrackName(const WalkTrack& track, size_t index);

// `names` with repeats renamed "<name>_2", "<name>_3"... (never colliding with another name).
// Names marked in `first_claim` (names as their tracks gave them, where the others were made
// legal by the caller) keep their own before any unmarked name does; otherwise the earlier
// name keeps it.
std::vector<std::string> UniqueNames(const std::vector<std::string>& names,
                                     const std::vector<bool>& first_claim = {});

// `text` with every byte that does not belong to a well-formed UTF-8 sequence replaced by
// U+FFFD, as the walk JSON writes it: glTF is JSON and must hold valid UTF-8 (a library caller's
// names may be any bytes).
std::string ValidUtf8(const std::string& text);

// q / |q|; q must be finite and non-zero (CheckWalk).
Quat Normalized(const Quat& q);

// The orientations the exports key on foot tracks when asked to (GltfOptions, MelOptions):
// each foot key turned as its character's body is at the key's frame, then tilted by the
// shortest rotation that takes the body's up onto the key's normal, so that the foot lies on
// its ground (the swing's mid key on the averaged normal) facing the body's heading.
class FootOrientation {
 public:
  // `walk` must pass CheckWalk and outlive this.
  explicit FootOrientation(const Walk& walk);
  // One unit quaternion per key of foot track `track`, in track order. The body's rotation
  // between its keys is interpolated (normalised linear, the short way), held before its first
  // key and after its last; a character without a body track turns as the identity. A key
  // whose normal is zero or not finite is not tilted.
  std::vector<Quat> Rotations(size_t track);

 private:
  Quat BodyAt(size_t body, double frame);
  const Walk& walk_;
  std::unordered_map<std::string, size_t> body_of_;        // character -> its first body track
  std::unordered_map<size_t, std::vector<size_t>> order_;  // body track -> KeyOrder
};

}  // namespace walk_export
}  // namespace footfall
