// The step generator: places every footstep of one or many characters on a terrain and keys the
// walk (foot IK targets and the body). The algorithm is listed as numbered steps in the
// top-level README.md ("The algorithm"); the generator's sources repeat the numbers in comments.
//
// It asks the terrain only through a TerrainSession, so the embedded engine and footfalld give
// the same walk. Each round of queries of a step is one batch call for all the characters of a
// pass (GenerateOptions::characters_per_pass); the RPC backend splits it into protocol-sized
// calls.
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "footfall/client/terrain_session.h"
#include "footfall/steps/character.h"
#include "footfall/steps/walk.h"
#include "footfall/terrain/samples.h"

namespace footfall {

// Characters walked together by default when the session answers in process: their stretch of
// terrain and their keys stay in the caches of the thread walking them from one step to the
// next.
constexpr int kInProcessCharactersPerPass = 250;

// The sample spacing a character walks well on, as a fraction of its step_length: it looks
// for each foothold within half a step of where it aims.
constexpr double kSeparationPerStep = 0.25;

// Steps per character when GenerateOptions::steps is unset: without a path, and the most with
// one (the walk ends at the goal).
constexpr int kDefaultSteps = 8;
constexpr int kMaxPathSteps = 10000;

// A start that may move (the default start, or GenerateOptions::start_may_move) moves to the
// nearest place within this many step lengths where the character can stand, looked for on a
// grid of half a step.
constexpr int kStartSearchSteps = 12;
// Bounds of GenerateOptions::start_frame and fps, for every caller (command line, C ABI,
// plugins): a frame of 1e300 put every key on one frame.
constexpr double kMaxStartFrame = 1e9;
constexpr double kMaxFps = 1e6;
// Bound of each coordinate of GenerateOptions::path and start: twice the terrain's coordinate
// range (the reach of its queries); farther, squared distances to a waypoint overflow and the
// heading turned away from the goal, and a start of 1e155 was "no samples".
constexpr double kMaxWaypointCoordinate = 2 * terrain::kMaxCoordinate;

// Whether every coordinate of p is within +-kMaxWaypointCoordinate (false for NaN).
inline bool WithinQueryReach(const Vec3& p) {
  return std::fabs(p.x) <= kMaxWaypointCoordinate && std::fabs(p.y) <= kMaxWaypointCoordinate &&
         std::fabs(p.z) <= kMaxWaypointCoordinate;
}

// How the generator's messages refer to the inputs that gave the start, heading, up and steps: the
// command line's flags by default; a scene names its file and field ("s.json: characters[0]:
// 'heading'"), the C ABI the request's field ("the request's 'heading'").
struct GenerateInputNames {
  std::string start = "--start";
  std::string heading = "--heading";
  std::string up = "--up";
  std::string steps = "--steps";
  std::string crowd_spacing = "--crowd-spacing";
  std::string scale = "--scale";  // the character's scale (ScaleCharacter), named in notes
};

struct GenerateOptions {
  // Where the start, heading and up came from, for messages.
  GenerateInputNames names;
  // Where the (first) character stands, snapped to the terrain. World space. Unset: the centre
  // of the top of the terrain's bounds (top along `up`), which may move (start_may_move).
  bool has_start = false;
  Vec3 start;
  // With a start: false, the characters stand where it snaps (a foot that cannot stand there
  // stops the walk at step 1); true, as for the default start: when the character cannot stand
  // there (a foot on ground steeper than max_slope_deg, or more than max_rise above or below
  // its rest position, or half a step beside it), it starts at the nearest point of a grid of
  // half a step around the start, within kStartSearchSteps step lengths in the plane across
  // `up`, where it can; if none, where the start snaps.
  bool start_may_move = false;
  // Facing direction, projected onto the start's tangent plane. World space, non-zero.
  Vec3 heading{0, 0, 1};
  // Waypoints to follow, in order (one point: a goal). World space. The heading turns toward
  // the current waypoint; the walk ends when the last one is reached (within half a step).
  std::vector<Vec3> path;
  // Steps per character; one step moves one gait group. < 0: kDefaultSteps without a path, up
  // to kMaxPathSteps (until the goal) with one.
  int steps = -1;
  double start_frame = 1;  // frame of the first keys
  double fps = 24;         // frames per second of the walk [Limit: > 0]
  // The walk's linear unit (Walk::unit, linear_units.h), or "" for none said. The walk carries
  // it; the generator's lengths are the terrain's and the character's whatever it is.
  std::string unit;
  // World up for bipeds (characters with align_to_normal false). Non-zero; normalised.
  Vec3 up{0, 1, 0};
  // Crowd: this many characters on a square grid around `start` (spacing `crowd_spacing`, or
  // 2 * reach when <= 0), each following the path shifted by its offset. Tracks then carry the
  // character id "c1".."cN".
  int crowd = 1;
  double crowd_spacing = 0;
  // Foot tracks also carry each key's orientation (AddFootRotations, foot_rotations.h), which
  // the walk JSON then writes.
  bool foot_rotations = false;
  // Threads for the generator's own work on large crowds: in process, passes walked in parallel,
  // one per thread; otherwise the per-character work between batches (the session splits its
  // batches by itself). The walk is the same whatever the count. [Limit: >= 1]
  int threads = 1;
  // Characters walked together: the crowd walks every step in groups of this many characters
  // (passes), so that each group's stretch of terrain stays in the caches; in process, with
  // threads > 1, each thread walks one pass at a time, else the passes follow one another.
  // < 0: all at once, which makes every round of queries of a step one batch call for the
  // whole crowd (the right choice over RPC). 0: chosen by the session,
  // kInProcessCharactersPerPass when it answers in process, else all at once. The walk is the
  // same whatever the value.
  int characters_per_pass = 0;
  // Called as the walk advances with (work done, total work), in steps times passes; may be
  // empty. Called from the generating thread and, for crowds walked in passes, from the batch
  // threads too, one call at a time: it must not assume the caller's thread. Work reaches the
  // total when every character arrived, stopped or walked its steps; a pass cut short by its
  // session failing (Walk::session_failed) leaves its steps left undone.
  std::function<void(int, int)> progress;
};

// Where GenerateWalk starts when GenerateOptions has no start (before snapping): the centre of
// the top face of the box [lo, hi] along the unit vector `up`.
Vec3 TopCentre(const Vec3& lo, const Vec3& hi, const Vec3& up);

// How far from the start the characters may stand when their start may move. [Units: wu]
double StartSearchRadius(const Character& character);

// The farthest a foot of `character` can move in one step: its longest try, aimed down as far
// as any try, plus the distance within which a foothold is taken. [Units: wu]
double MaxStepTravel(const Character& character);

// Generates the walk into *out (replacing it). Returns kOk when the walk was generated, even if
// it stopped early: then out->stopped says at which step and position, and every key up to that
// step is kept. Other statuses: kInvalidArgument (bad options, message in *error), or the
// session's failure (kUnavailable, kUnknownTerrain ...; *error from last_error()). `error` may
// be null.
Status GenerateWalk(TerrainSession& session, TerrainHandle terrain, const Character& character,
                    const GenerateOptions& options, Walk* out, std::string* error);

}  // namespace footfall
