// Preparing a walk for export, shared by the glTF and MEL writers: input checks, the order in
// which a track's keys are written, and unique node names.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall {
namespace walk_export {

// Sets *error to `message` when error is non-null.
void SetError(std::string* error, const std::string& message);

// kOk when fps is finite and > 0 and every key has a finite frame and position, and every body
// key (and every key of a foot track that carries rotations) a finite, non-zero quaternion;
// otherwise kInvalidArgument with the track and key named.
Status CheckWalk(const Walk& walk, std::string* error);

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

}  // namespace walk_export
}  // namespace footfall
