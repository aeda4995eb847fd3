// Writes a walk in the format its file extension names.
#pragma once

#include <string>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall {

// Dispatches on the extension of `path` (case-insensitive): ".gltf" and ".glb" to WriteGltf,
// ".mel" to WriteMel. Any other extension (".json" included: the JSON writer lives with the
// step generator) returns kInvalidArgument with a message naming the path and the supported
// extensions. `error` may be null.
Status WriteWalk(const Walk& walk, const std::string& path, std::string* error);

struct WalkExportOptions {
  // Feet keyed with rotations too (GltfOptions::foot_rotations, MelOptions::foot_rotations).
  bool foot_rotations = false;
};

// As above, with `options`.
Status WriteWalk(const Walk& walk, const std::string& path, const WalkExportOptions& options,
                 std::string* error);

// True when WriteWalk knows the extension of `path`.
bool IsWalkExportPath(const std::string& path);

}  // namespace footfall
