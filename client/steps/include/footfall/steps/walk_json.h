// The walk as JSON, footfall's canonical interchange (read by the viewer and the Blender
// plugin). Format "footfall-walk", version 1, documented in the top-level README ("Walk JSON"):
//   {"format": "footfall-walk", "version": 1, "fps": 24, "stopped": "",
//    "tracks": [{"name": "L1", "kind": "foot", "keys": [{"frame": 1, "phase": "start",
//                "position": [x, y, z], "normal": [nx, ny, nz]}, ...]},
//               (foot keys given their orientations, AddFootRotations, add "rotation"),
//               {"name": "body", "kind": "body", "keys": [{"frame": 1, "position": [x, y, z],
//                "rotation": [qx, qy, qz, qw]}, ...]}]}
// Crowd tracks add "character": "c1"; a walk whose unit is known adds "unit": "cm" after "fps"
// (Walk::unit). Numbers are written so they read back exactly.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "footfall/steps/walk.h"
#include "footfall/terrain/status.h"

namespace footfall {

constexpr int kWalkFormatVersion = 1;

// The walk as JSON text (one line per key, ending in a newline). Keys are written in ascending
// frames; of keys on the same frame only the last is written (as the glTF and MEL exporters key
// them), so the text always reads back with ParseWalkJson.
std::string WalkToJson(const Walk& walk);

// WalkToJson(walk) piece by piece: sink(piece) for each of about a megabyte, in order, so that
// a caller can write or copy the text without holding it twice. Stops, returning false, as soon
// as sink returns false. The pieces are formatted on `threads` threads (0: one per core; a
// walk of fewer than about 30,000 keys on one), the same text on any number; sink is called
// from the calling thread.
bool EmitWalkJson(const Walk& walk, const std::function<bool(std::string_view)>& sink,
                  int threads = 0);

// Writes WalkToJson(walk) to `path`, as it is built (never whole in memory: a crowd's walk runs
// to gigabytes). kIoError with a message naming the file on failure.
Status WriteWalkJson(const Walk& walk, const std::string& path, std::string* error);

// Keys lie within +-this of the origin: terrain samples within +-5e14 (terrain::kMaxCoordinate),
// and what a walk adds above them.
constexpr double kMaxKeyCoordinate = 1e15;

// A foot track's foot_length lies in [0, this], as a character's does.
constexpr double kMaxFootLength = 1e9;

// Parses walk JSON. `source` names it in errors: "SOURCE:LINE:COLUMN: malformed JSON: ..." for
// text that is not JSON, "SOURCE: tracks[2].keys[5].position: expected an array of 3 numbers
// (line 8)" for a wrong structure: the line (1-based) where that value starts, or, for a missing
// field, where the object without it starts. Frames must increase along each track, positions
// lie within +-kMaxKeyCoordinate, a foot track's foot_length within [0, kMaxFootLength], foot
// normals must be non-zero vectors and body rotations non-zero quaternions (both finite, read as
// written, not normalised). kParseError for malformed or unsupported input. Keys are read as they
// are parsed: the text and the walk are all it holds.
Status ParseWalkJson(const std::string& text, const std::string& source, Walk* out,
                     std::string* error);

namespace detail {
// ParseWalkJson building the whole document before reading it (about five times the text in
// memory, where ParseWalkJson holds little more than the walk): the same result and the same
// messages, for comparison.
Status ParseWalkJsonWhole(const std::string& text, const std::string& source, Walk* out,
                          std::string* error);
}  // namespace detail

// Reads and parses a walk file. kIoError when it cannot be read.
Status ReadWalkJson(const std::string& path, Walk* out, std::string* error);

}  // namespace footfall
