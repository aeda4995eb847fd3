// Character: what the step generator needs to know about a walker, read from a character file
// (JSON, format "footfall-character", version 1; the fields are documented in
// client/steps/README.md).
//
// Character space: +Z forward, +Y up, +X left (right-handed, as a Maya character facing +Z).
// Lengths are world units [wu]; angles are degrees.
#pragma once

#include <string>
#include <vector>

#include "footfall/terrain/status.h"
#include "footfall/terrain/vec3.h"

namespace footfall {

constexpr int kCharacterFormatVersion = 1;

struct FootSpec {
  std::string name;  // track name in the walk, unique within the character
  // Rest position relative to the body's ground point (the terrain point under the body),
  // character space. [Units: wu] y is usually 0. A walk keeps the body over the feet's
  // centroid, so it places feet at their rests less RestCentroid (the same for symmetric feet).
  Vec3 rest;
};

struct Character {
  std::string name;
  std::vector<FootSpec> feet;
  // Gait groups in stepping order: indices into `feet`. Every foot is in exactly one group; the
  // feet of a group step together, group after group, round and round.
  std::vector<std::vector<int>> gait;
  // Foot pairs sharing a central locator (one or two feet each; every foot in exactly one).
  std::vector<std::vector<int>> pairs;
  double step_length = 0.6;   // distance a foot travels in one step once walking [Limit: > 0]
  double step_height = 0.15;  // swing arc height above the start-end chord [Limit: > 0]
  double body_height = 0.9;   // body above the feet's centroid, along the body's up [Limit: >= 0]
  int frames_per_step = 12;   // frames from lift-off to touch-down [Limit: >= 2]
  // true (multipeds): the body's up follows the terrain under the feet (the plane fitted to
  // them; README, "The algorithm", step 11), so it can walk on walls, ceilings and around
  // spheres. false (bipeds): the body stays upright along the world up axis (--up).
  bool align_to_normal = false;
  // Slope awareness. A step whose ground rises or falls more than slope_threshold_deg along the
  // heading is shortened to slope_step_scale * step_length. Footholds whose normal leans more
  // than max_slope_deg from the feet's up, or which rise or fall more than max_rise along it,
  // are refused (a shorter step is tried, then the walk stops).
  double slope_threshold_deg = 15;  // [Limit: 0..90]
  double slope_step_scale = 0.6;    // [Limit: (0, 1]]
  double max_slope_deg = 50;        // [Limit: (0, 180)]
  double max_rise = 0.35;           // [Units: wu] [Limit: > 0]
  // No foot is ever keyed farther than `reach` from the body. [Units: wu] [Limit: > the rest
  // distance of every foot from the body]
  double reach = 1.2;
  // The heading turns by at most this much per step when following a path. [Limit: (0, 180]]
  double max_turn_deg = 30;
  // The length of each foot's sole along the heading, its foothold at the middle: a foothold
  // whose heel or toe would stand past a stair's nose or in a riser moves along its tread until
  // the sole fits (README, "The algorithm", step 8). 0: point feet. [Units: wu] [Limit: >= 0]
  double foot_length = 0;
  // The width of each foot's sole across the heading, its foothold at the middle: a foothold
  // whose sole would hang over a side edge (the end of a tread beside the heading, a beam's
  // edge) moves across until it fits. Needs a foot_length. 0: no width. [Units: wu]
  // [Limit: >= 0]
  double foot_width = 0;
};

// Parses a character file's text. `source` names it in errors ("FILE: field: what was
// expected", "FILE:LINE:COLUMN: malformed JSON: ..."). Returns kParseError for malformed JSON,
// an unknown field (at the top level or in a foot), a missing or mistyped field or a version
// other than kCharacterFormatVersion; kInvalidArgument for values out of range or inconsistent
// gait/pairs.
Status ParseCharacter(const std::string& text, const std::string& source, Character* out,
                      std::string* error);

// The centroid of the feet's rest positions: where a walk puts the body's ground point.
Vec3 RestCentroid(const Character& c);

// Reads and parses a character file. kIoError when it cannot be read.
Status LoadCharacter(const std::string& path, Character* out, std::string* error);

// The range of ScaleCharacter's scale.
constexpr double kMinCharacterScale = 1e-6;
constexpr double kMaxCharacterScale = 1e6;

// Multiplies every length of `c` by `scale`: its feet's rests, step_length, step_height,
// body_height, max_rise, reach, foot_length and foot_width (angles, frames and the gait stay). The
// same character on a terrain in other units (100: a character file in metres on a terrain in
// centimetres), or bigger or smaller. kInvalidArgument, naming the field, when `scale` is
// outside [kMinCharacterScale, kMaxCharacterScale] or a length would leave the range a character
// file allows; `c` is then unchanged.
Status ScaleCharacter(double scale, Character* c, std::string* error);

}  // namespace footfall
