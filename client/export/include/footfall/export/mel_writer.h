// Maya MEL export of a walk: `source walk.mel` creates one locator per track under a root group
// and keys it, so an animator can constrain IK handles and the body to the locators.
#pragma once

#include <string>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall {

// Writes `walk` to `path` as a MEL script that, when sourced:
// 1. sets the scene time unit to the walk's fps when Maya has a unit for it (15 game, 24 film,
//    25 pal, 30 ntsc, 48 show, 50 palf, 60 ntscf, other whole rates Maya 2017+ knows as
//    "<fps>fps"); otherwise it prints a MEL warning and keeps the scene's unit. Sets the
//    playback range to the walk's frames;
// 2. creates a root transform "footfall_walk" and, for crowd walks, one transform per character
//    under it;
// 3. per track, creates a locator (`spaceLocator -n`), parents it, and keys translateX/Y/Z at
//    every key frame (bodies, and feet with MelOptions::foot_rotations, also rotateX/Y/Z, in
//    rotate order ZXY so that heading is rotateY alone and an upright body is never at gimbal
//    lock: the quaternion as Euler ZXY degrees, unwrapped so consecutive keys take the shortest
//    turn). Frames are written as they are in the
//    walk. Every key has linear in and out tangents, as the glTF export's LINEAR samplers.
//    A walk with a unit (Walk::unit: "m" for the shipped characters on a terrain in metres)
//    is keyed with the scene's linear unit set to it, the user's put back after, as for
//    angles: Maya converts, so a walk in metres sourced into a centimetre scene keeps its size
//    (100 scene units a metre). A walk without one is keyed in the scene's unit, one walk unit
//    to one scene unit.
// Frames and values are MEL decimals without exponent, with the fewest digits that read back as
// the same double (a walk in tiny or huge units keeps full precision).
// Node names are sanitised to Maya names ([A-Za-z_][A-Za-z0-9_]*; other characters become '_')
// and made unique in the file and against the root group's name (a foot named footfall_walk
// becomes footfall_walk_2). Strings and comments are valid UTF-8 (a byte outside any
// well-formed UTF-8 sequence becomes U+FFFD, as in the walk JSON). The script uses the names Maya
// returns, so it still works when the scene already holds nodes of the same names. Keys on the same
// frame: the last one wins. Returns kInvalidArgument (with `*error` set) for fps <= 0, NaN/Inf
// values, a zero quaternion or a walk unit Maya does not know (Walk::unit); kIoError
// naming `path` when the file cannot be written. `error` may be null.
Status WriteMel(const Walk& walk, const std::string& path, std::string* error);

struct MelOptions {
  // true: foot locators are keyed with rotations too (rotateX/Y/Z in rotate order ZXY, as
  // bodies), each foot on its ground facing its body's heading, as GltfOptions::foot_rotations
  // turns glTF's foot nodes.
  bool foot_rotations = false;
};

// As above, with `options`.
Status WriteMel(const Walk& walk, const std::string& path, const MelOptions& options,
                std::string* error);

}  // namespace footfall
