// glTF 2.0 export of a walk: one node per track (foot IK targets and bodies), animated by one
// animation named "walk" with LINEAR samplers. Passes the Khronos glTF validator.
#pragma once

#include <string>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall {

struct GltfOptions {
  // true: .glb (one binary container, the animation data in its BIN chunk).
  // false: .gltf JSON with the buffer embedded as a base64 data URI, so the file is
  // self-contained (no side .bin to lose when the file is moved).
  bool binary = false;
};

// Writes `walk` to `path` as glTF 2.0.
// - Nodes: one per track, in track order, all roots of the single scene. Names are the track
//   name, or "character/name" for crowd tracks; a repeated name gets a "_2", "_3"... suffix.
//   Names and the stop reason are written as valid UTF-8, as in the walk JSON: a byte that
//   belongs to no well-formed UTF-8 sequence becomes U+FFFD.
//   Each node's rest translation (and rotation for bodies) is its first key.
// - Channels: feet animate translation; bodies translation and rotation (normalised
//   quaternions). Times in seconds = frame / fps. glTF needs strictly increasing times: keys are
//   ordered by frame (stable) and of several keys on the same frame only the last one is kept;
//   distinct frames whose times are the same float (a start frame far from 0 at a high fps) are
//   refused (kInvalidArgument), as merging them would lose keys. Positions are floats too: at
//   coordinates near 4e6 they move by up to 0.25 (MaxFloatRounding).
// - Node extras hold {"kind", "character", "track"}; the animation's extras hold {"fps"} and
//   {"stopped"} when the walk stopped early. World units are written unchanged (glTF metres).
// Returns kInvalidArgument (with `*error` set) for fps <= 0, a negative frame, NaN/Inf values or
// a zero quaternion; kLimitExceeded when writing it would need more memory than the process has
// free (AvailableMemoryBytes); kIoError naming `path` when the file cannot be written. `error` may
// be null.
Status WriteGltf(const Walk& walk, const std::string& path, const GltfOptions& options,
                 std::string* error);

// As above, binary when `path` ends in ".glb" (any case), JSON otherwise.
Status WriteGltf(const Walk& walk, const std::string& path, std::string* error);

// [Units: wu] The farthest any key of `walk` moves once its position is rounded to float, as
// glTF stores it (0 for a walk near the origin at ordinary spacings).
double MaxFloatRounding(const Walk& walk);

// [Units: frames] The farthest any key of `walk` moves in time once its time (frame / fps) is
// rounded to float seconds, as glTF stores it (0 for frames and rates of ordinary size; half a
// frame from frame 2^24 on).
double MaxTimeRounding(const Walk& walk);

}  // namespace footfall
