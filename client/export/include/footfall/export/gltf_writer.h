// glTF 2.0 export of a walk: one node per track (foot IK targets and bodies), animated by one
// animation named "walk" with LINEAR samplers. Passes the Khronos glTF validator.
//
// Precision at real-world coordinates: glTF animation data is float32, which near 1e5 keeps
// positions only to about 8 mm and near 5e5 to 3-6 cm (feet would jitter and planted feet
// slide). A walk with any key coordinate beyond +-kGltfLocalExtent therefore gets one root node,
// "footfall_origin", whose translation (a JSON number, full double precision) is the walk's
// origin (GltfOrigin); the track nodes are its children and their keys are relative to it, so
// their floats are small and precise: origin + key reads back within 1e-4 of the walk's position
// (for walks spanning up to 2 * kGltfLocalExtent). A walk near the origin is written as before,
// without a root node.
#pragma once

#include <string>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"
#include "footfall/terrain/vec3.h"

namespace footfall {

struct GltfOptions {
  // true: .glb (one binary container, the animation data in its BIN chunk).
  // false: .gltf JSON with the buffer embedded as a base64 data URI, so the file is
  // self-contained (no side .bin to lose when the file is moved).
  bool binary = false;
  // [Units: bytes] The largest .glb written: its header and chunk lengths are 32-bit, so one
  // larger would be written with lengths wrapped round, corrupt. A walk whose .glb would be
  // larger (its buffer and about 2 KB of JSON a track) is refused, naming .gltf, which has no
  // such limit.
  double max_glb_bytes = 4294967295.0;
  // true: foot nodes are keyed with rotations too, each foot on its ground facing its body's
  // heading (the body's rotation at the key's frame, tilted by the shortest rotation that takes
  // the body's up onto the key's normal). false: feet have translation channels only.
  bool foot_rotations = false;
};

// [Units: wu] [Limit: > 0] Beyond this |coordinate| a walk's glTF gets a root origin node: below
// it a float keeps every coordinate within 2^-15 (3.1e-5), so a 3D key within 5.3e-5, of its
// double value; at twice it a float's step is already 2.4e-4.
constexpr double kGltfLocalExtent = 1024;

// [Units: wu] [(x, y, z), world] The translation of the root node WriteGltf gives `walk`; (0, 0,
// 0) when it writes none. Per axis: 0 when the keys' coordinates on that axis are all within
// +-kGltfLocalExtent (so a walk near the origin gets no root, and an axis that needs no offset,
// often the height, keeps its values as they are); otherwise the centre of the keys' bounds on
// that axis rounded to the nearest integer: exact and short in JSON, and exact as a float up to
// 2^24 (1.7e7, beyond any UTM coordinate), so readers that hold node translations as floats
// (Blender, most engines) keep the origin exact too. Non-finite coordinates are ignored.
Vec3 GltfOrigin(const Walk& walk);

// Writes `walk` to `path` as glTF 2.0.
// - Nodes: one per track, in track order (node i is track i). Names are the track name, or
//   "character/name" for crowd tracks; a repeated name gets a "_2", "_3"... suffix. When
//   GltfOrigin(walk) is (0, 0, 0) they are the roots of the single scene (the layout of files
//   near the origin). Otherwise one more node, last, named "footfall_origin" (suffixed if a
//   track has that name), is the scene's only root: its translation is GltfOrigin(walk), its
//   children are the track nodes, whose translations (rest pose and keys) are relative to it,
//   and its extras hold {"kind": "origin", "origin": [x, y, z]} (the same numbers). A key's
//   world position is the root's translation (double) + the child's key (float).
//   Names and the stop reason are written as valid UTF-8, as in the walk JSON: a byte that
//   belongs to no well-formed UTF-8 sequence becomes U+FFFD.
//   Each node's rest translation (and rotation for bodies, and feet with foot_rotations) is
//   its first key.
// - Channels: feet animate translation (and rotation with GltfOptions::foot_rotations); bodies
//   translation and rotation (normalised quaternions). Times in seconds = frame / fps. glTF needs
//   strictly increasing times: keys are ordered by frame (stable) and of several keys on the same
//   frame only the last one is kept; distinct frames whose times are the same float (a start frame
//   far from 0 at a high fps) are refused (kInvalidArgument), as merging them would lose keys.
//   Positions are floats too, relative to the origin node if any: a walk spanning kilometres still
//   moves (MaxFloatRounding).
// - Node extras hold {"kind", "character", "track"}; the animation's extras hold {"fps"} and
//   {"stopped"} when the walk stopped early. Lengths are written as they are (taken as glTF's
//   metres), unless the walk's unit (Walk::unit) is another: then they are converted to metres
//   (keys, the origin node, the feet's foot_length), so a walk in centimetres keeps its size in
//   a reader that takes glTF as glTF is (Blender, Unreal).
// Returns kInvalidArgument (with `*error` set) for an unknown linear unit, fps <= 0, a negative
// frame, NaN/Inf values or a zero quaternion; kLimitExceeded when writing it would need more memory
// than the process has free (AvailableMemoryBytes); kIoError naming `path` when the file cannot be
// written. `error` may be null.
Status WriteGltf(const Walk& walk, const std::string& path, const GltfOptions& options,
                 std::string* error);

// As above, binary when `path` ends in ".glb" (any case), JSON otherwise.
Status WriteGltf(const Walk& walk, const std::string& path, std::string* error);

// [Units: wu] The farthest any key of `walk` moves once its position is rounded to float, as
// glTF stores it: relative to GltfOrigin(walk), added back in double. Below 1e-4 for a walk
// near the origin or within 2 * kGltfLocalExtent of its own centre; more for a walk spanning
// kilometres (about 0.25 across 4e6).
double MaxFloatRounding(const Walk& walk);

// [Units: frames] The farthest any key of `walk` moves in time once its time (frame / fps) is
// rounded to float seconds, as glTF stores it (0 for frames and rates of ordinary size; half a
// frame from frame 2^24 on).
double MaxTimeRounding(const Walk& walk);

}  // namespace footfall
