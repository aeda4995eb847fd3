// The orientation of each foot key: what the exports key on feet when asked to, and what the
// walk JSON carries on foot keys after AddFootRotations. Part of the walk data model (with
// walk.h): the generator and the exporters both use it.
#pragma once

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "footfall/steps/walk.h"

namespace footfall {

// Each foot key turned as its character's body is at the key's frame, then tilted by the
// shortest rotation that takes the body's up onto the key's normal, so that the foot lies on
// its ground (the swing's mid key on the averaged normal) facing the body's heading.
class FootOrientation {
 public:
  // Every body rotation of `walk` must be finite and non-zero (as the exporters check);
  // `walk` must outlive this.
  explicit FootOrientation(const Walk& walk);
  // One unit quaternion per key of foot track `track`, in track order: the track's own
  // rotations when it carries one per key (AddFootRotations, or a walk JSON that has them),
  // normalised; otherwise computed. The body's rotation between its keys is interpolated
  // (normalised linear, the short way), held before its first key and after its last; a
  // character without a body track turns as the identity. A key whose normal is zero or not
  // finite is not tilted.
  std::vector<Quat> Rotations(size_t track);

 private:
  Quat BodyAt(size_t body, double frame);
  const Walk& walk_;
  std::unordered_map<std::string, size_t> body_of_;        // character -> its first body track
  std::unordered_map<size_t, std::vector<size_t>> order_;  // body track -> KeyOrder
};

// Gives every foot track of `walk` its keys' orientations (WalkTrack::rotations, one per key,
// as FootOrientation computes them); the walk JSON then writes them. Body rotations that are
// not finite or are zero count as the identity.
void AddFootRotations(Walk* walk);

}  // namespace footfall
