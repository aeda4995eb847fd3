// Reads a walk JSON file (the step generator's output) into the Walk data model:
//   {"fps": 24, "stopped": "...",
//    "tracks": [{"name": "L1", "kind": "foot", "character": "",
//                "keys": [{"frame": 1, "phase": "start", "position": [x, y, z],
//                          "normal": [x, y, z]}, ...]},
//               {"name": "body", "kind": "body",
//                "keys": [{"frame": 1, "position": [x, y, z], "rotation": [qx, qy, qz, qw]}]}]}
// A minimal reader for the viewer; the step generator's shared reader replaces it once merged.
#pragma once

#include <string>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall::viewer {

// Loads `path` into *out. kIoError when it cannot be read; kParseError for malformed JSON
// ("FILE:LINE:COLUMN: ...") or a wrong structure ("FILE: tracks[0].keys[2].position: expected
// an array of 3 finite numbers"). Keys must come in ascending frames; fps must be > 0.
Status ReadWalkJson(const std::string& path, Walk* out, std::string* error);

}  // namespace footfall::viewer
