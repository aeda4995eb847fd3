// The step generator's internals, shared by its source files: the tuning constants, a walking
// character (Agent), one foot's move in a step (Move) and the Generator that walks them. The
// numbered comments match the numbered list of "The algorithm" in the top-level README.md;
// each step lives in one file:
//   generator.cpp            the run: passes of characters, one step at a time (5-11 in order)
//   generator_setup.cpp      1-4: start, heading, feet and body snapped to the terrain
//   generator_footholds.cpp  5-8: steering along the path, foothold queries and their judging
//   generator_keys.cpp       9-11: swing arcs, foot and body keys
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "footfall/steps/generator.h"
#include "footfall/terrain/batch_pool.h"
#include "footfall/terrain/text_stream.h"
#include "frame_math.h"

namespace footfall::steps_detail {

// Stop reasons and notes (written into walk files): the "C" locale, never cut short.
using Text = TextStream;

// Foothold queries per foot and step, in turn: the step vector scaled (shorter, then longer:
// over a stair's riser, then shorter still), then aimed down by `drop` times max_rise along the
// body's up (down a stair's nose, or over a convex edge onto the face below it).
struct Attempt {
  double scale, drop;
};
inline constexpr int kMaxAttempts = 9;
inline constexpr Attempt kAttempts[kMaxAttempts] = {{1.0, 0},   {0.6, 0},   {1.35, 0},
                                                    {0.3, 0},   {1.0, 0.5}, {0.6, 0.5},
                                                    {0.3, 0.5}, {1.0, 1.0}, {0.6, 1.0}};
// The first of the tries aimed down (a full step).
inline constexpr int kFirstDownAttempt = 4;
static_assert(kAttempts[kFirstDownAttempt].scale == 1 && kAttempts[kFirstDownAttempt].drop > 0 &&
                  kAttempts[kFirstDownAttempt - 1].drop == 0,
              "the first try aimed down");
// A foothold is looked for within this fraction of step_length of where the foot aims.
inline constexpr double kFootholdTolerance = 0.5;
// A biped's locator snapped back onto its feet's nose looks for the ground below along this
// many lines, evenly from the snap to its place (LandLocators).
inline constexpr int kLandLines = 4;
// A biped's locator on a riser ahead looks for the tread above (below) along a line this share
// of foot_length behind (before) the riser's face (ClimbLocators).
inline constexpr double kClimbDepth = 0.5;
inline constexpr int kMaxClimbPoints = 32;  // points up that line, at most
// Ground leaning less than this (the sine of its normal's angle across the heading) is taken as
// flat by ClimbedAside: a tread, not a slope the locator slides along.
inline constexpr double kFlatLean = 0.1;
inline constexpr int kMaxRaises = 8;     // swing arc raises before giving up
inline constexpr double kRaise = 0.5;    // raise per round, in step heights
inline constexpr double kSlide = 0.25;   // slide per round toward a blocked half's end (of the way)
inline constexpr int kMaxHooks = 3;      // swing arcs hooked out from a face, after the raises
inline constexpr double kHookOut = 0.5;  // a hooked mid key's distance out, per height above
inline constexpr double kAlikeCos = 0.7071;  // footholds whose normals are within 45 deg face alike
// A body key keeps at least this fraction of body_height from the terrain (measured as arcs
// are, from its nearest sample); nearer, it is raised along its up, in up to kBodyRounds rounds
// of at most body_height each, and never beyond reach of a foot.
inline constexpr double kBodyClearance = 0.5;
inline constexpr int kBodyRounds = 3;
// Room for an upright body (bipeds): points of its spine, from half body_height above the
// feet's centroid up to the body, at most this many and no farther apart than the terrain's
// gap, are snapped; a nearest sample on the spine's line (within the gap), above every foot by
// more than the gap and below the body is terrain between the feet and the body, and the walk
// stops before that step (a biped walking under a slab lower than its body had its feet under
// it and its body over it). Not tried for multipeds, whose bodies lean with the terrain and
// whose feet wrap around edges.
inline constexpr size_t kMaxSpineChecks = 17;
// Points checked along each start-mid-end arc, evenly spaced: at least kMinArcChecks, and as many
// more as keep them no farther apart than the terrain's gap (about twice its sample spacing), up
// to kMaxArcChecks (ArcChecks). Between two check points an arc may graze a sharp edge by about
// their spacing: seven points on a 1.8 m stride over stairs sampled every 2 cm let its last stretch
// pass 7.5 cm through a nose. Each point is snapped: its clearance is measured along the normal
// of its nearest sample, and a Snap answer elsewhere proves only that no sample lies closer to
// that point than the answer, which bounds neither which sample is nearest here nor its normal.
// (A point between two points of the same straight half that share a nearest sample shares it
// too, Voronoi cells being convex; but measured on the bench's ground, samples a third of a step
// apart, that would spare at most one query in seven, for an extra round of queries.)
inline constexpr size_t kMinArcChecks = 7;
inline constexpr size_t kMaxArcChecks = 63;

// The number of points checked along an arc of `length` (its longer half twice), no farther
// apart than `gap`: 7, 15, 23, ... 63, so that the seven points of the shortest arcs (at
// eighths) are always among them.
// [Units: length, gap in wu]
inline size_t ArcChecks(double length, double gap) {
  static_assert((kMaxArcChecks + 1) % 8 == 0 && (kMinArcChecks + 1) == 8, "checks at eighths");
  if (!(gap > 0) || !std::isfinite(length)) return kMinArcChecks;
  const double eighths = std::ceil(length / gap / 8);
  constexpr double kMost = (kMaxArcChecks + 1) / 8.0;
  return 8 * static_cast<size_t>(eighths > 1 ? std::min(eighths, kMost) : 1.0) - 1;
}

// The j-th of an arc's `checks` points, as a fraction of the arc (0: its start key, 0.5: its
// mid key, 1: its end key).
inline double ArcS(size_t j, size_t checks) {
  return static_cast<double>(j + 1) / static_cast<double>(checks + 1);
}
// Required clearance at each check point, as a fraction of the arc's nominal clearance there
// (the step height at the mid key, falling linearly to 0 at the start and end keys).
inline constexpr double kClearanceFraction = 0.25;
// A step_length more than this many times the longest step the reach allows on level ground
// (Generator::LongestStepInReach) is worth a note: its steps are all shortened.
inline constexpr double kReachNoteMargin = 1.05;
// A rest whose y (along the up) exceeds this share of the largest rest across the up is worth
// a note (most likely written Z-up).
inline constexpr double kOffGroundRestShare = 0.5;
// Two feet resting closer than this share of the reach are worth a note (they plant on the
// same samples).
inline constexpr double kNearRestsShare = 0.1;
// Terrain samples farther apart than this many step lengths, or a terrain smaller across than
// the reach, are worth a note: most likely the terrain and the character are in different units.
inline constexpr double kUnitsNoteSpacingSteps = 4;
// Steer: a turn is tried at its whole and then in kTurnShares - 1 smaller shares, and the
// largest that keeps every pair's feet at least kMinPairGap of their rest gap apart is taken.
inline constexpr int kTurnShares = 8;
// Ground whose up lies within this many degrees of the world up is a floor for path walks:
// waypoints off the terrain are aimed at across it, their height along the world up ignored.
inline constexpr double kFloorUpDeg = 60;
// [Units: deg] How far off its step's direction, along its ground, a foothold may lie
// (Generator::Judge).
inline constexpr double kMaxSidewaysDeg = 40;
inline constexpr double kMinPairGap = 0.5;
// A step shorter than this fraction of step_length is a step in place: no foothold query.
inline constexpr double kInPlace = 0.02;
// A foothold rises or drops up to max_rise times (1 + this): samples are stored in float, so a
// riser modelled exactly max_rise high measured 0.40000001 of 0.4 and was refused as a cliff.
inline constexpr double kRiseRounding = 1e-6;
// Move::query of a move not asked this round.
inline constexpr size_t kNoQuery = ~size_t{0};
// Per-character loops split across threads only from this many items (a hand-over costs
// ~20 us).
inline constexpr size_t kMinParallel = 512;

// "(x, y, z)" to 4 decimals, for messages.
std::string Point(const Vec3& p);
// `value` to 3 significant digits, or to as many more as it takes to differ from `limit`, which
// it breaks: "leans 100.0001 deg, more than max_slope_deg 100", never "leans 100 ... 100".
std::string Beyond(double value, double limit);
// For ground facing away from the character's up (more than 120 degrees): what would make it
// so where the ground should face up (an underside is often just that: a log's, a beam's), and
// for a character `aligned_to_normal`, a beam or ledge narrower than it; "" below 120 degrees.
std::string FacingDownHint(double slope_deg, bool aligned_to_normal);

// One walking character.
struct Agent {
  std::string id;                       // "" for a single character, else "c1".."cN"
  bool left_out = false;                // a crowd's character starting on another: no tracks
  Vec3 ground;                          // the body's ground point: centroid of the planted feet
  Vec3 up;                              // the up of the feet's frame (FeetUp)
  Vec3 body_up;                         // the body's up (GaitCycleUp)
  Vec3 fitted_up;                       // BodyUp of the feet as they stand
  Vec3 forward;                         // the body's heading, unit, perpendicular to up
  std::vector<Vec3> foot, foot_normal;  // planted feet
  std::vector<Vec3> path;
  // Each waypoint's distance from the terrain (its nearest sample; infinite for one beyond the
  // reach of terrain queries): one lying on the terrain is reached only when near in 3D too.
  std::vector<double> path_off;
  size_t waypoint = 0;
  // The nearest the ground has come to the current waypoint (in 3D), by a quarter step at a
  // time, and the step it did: a walk that comes no nearer for Generator::window_steps_ steps
  // has no way there.
  size_t nearest_waypoint = SIZE_MAX;
  double nearest = 0;
  double nearest_level = 0;  // the same seen from above: across the world up
  int nearest_step = 0;
  // This step's stride, as a share of a full one (Steer): below 1 while the waypoint lies inside
  // the circle the body turns on at full stride, 0 to turn on the spot.
  double stride = 1;
  bool walking = true;  // false once stopped or arrived
  int waits = 0;        // steps in a row its group stepped in place, waiting for a planted foot
  int still = 0;        // steps in a row no foot of it moved (waits, turns on the spot included)
  // Where the body was at step `window_step`, the first step since it was last half a step or
  // more from the previous such place: a body that stays within half a step of it for
  // Generator::window_steps_ steps is milling about at a dead end.
  Vec3 window_from;
  int window_step = -1;
  std::string stopped;   // why it stopped early ("" when it did not)
  int stopped_step = 0;  // the step it stopped at
  bool failed = false;   // stopped by the serving engine's failure, not by the terrain
  size_t first_track = 0;
};

// One foot of one agent in the current step.
struct Move {
  size_t agent;
  int foot;
  Attempt attempt = kAttempts[0];  // how this round aims the step (retries change it)
  int attempts = 0;
  bool done = false;
  bool failed = false;
  // Why the foot was refused: the first foothold refused (the step as meant), or, when every
  // foothold before was a gap, the first one found but refused (steep, high, out of reach, an
  // arc that cannot clear), which says more.
  std::string reason;
  bool reason_is_gap = false;
  // A try found a foothold refused only because a planted foot would be left beyond reach: the
  // character may wait for that foot (Finish).
  bool held_by_planted = false;
  Vec3 end, end_normal;  // the accepted foothold
  Vec3 mid, mid_normal;
  int hooks = 0;            // times the arc's mid key hooked out from a face (ClearArcs)
  Vec3 ideal;               // the last query's ideal point
  Vec3 step;                // the last query's step vector
  size_t query = kNoQuery;  // index of this round's foothold answer, or kNoQuery
  // A foothold accepted but lined up with (or across) its pair's other foot: the query is
  // asked again aimed outward by `outward` across the heading (0: not asked; below 0: not
  // again in this try, whose outward foothold was refused after all: Reopen), and this one
  // (`lined_up`, its gap as a share of the rest gap) is kept unless that does better
  // (`outward_kept`).
  double outward = 0;
  bool lined_up = false;
  bool outward_kept = false;
  double lined_up_gap = 0;
  Vec3 lined_up_point, lined_up_normal;
  // Sole fitting (8, end; a character with a foot_length): 0 not yet checked, 1 checked, 2
  // moved along its ground so that the sole fits, -1 once a moved foothold was refused after
  // all (arc, reach): this step's tries then keep their footholds as found.
  int sole = 0;
  // A foothold at the edge of the ground the foot stands on, its toe over the drop (FitSoles):
  // the foot tries stepping down past it first, and stands there only if every such try is
  // refused (Generator::StandAtEdge).
  bool at_edge = false;
  Vec3 edge_point, edge_normal;
};

// mv's accepted foothold refused after all (beyond reach, or its arc cannot clear): a foothold
// its outward retry found gives way to the lined-up one it bettered, and one moved for its sole
// (FitSoles) to the foothold as found, each asked again in the same try (without aiming
// outward, without moving it); any other starts its next try afresh.
void Reopen(Move& mv);

class Generator {
 public:
  // Walks `agents` (filled by Setup) into *walk.
  Generator(TerrainSession& session, TerrainHandle terrain, const Character& c,
            const GenerateOptions& o, std::vector<Agent>* agents, Walk* walk)
      : session_(session),
        terrain_(terrain),
        c_(c),
        o_(o),
        walk_(*walk),
        agents_(*agents),
        threads_(o.threads) {}

  // A copy walks passes of its own, sharing the agents and the walk (WalkPassesInParallel).
  Generator(const Generator&) = default;

  Status Run(std::string* error);

 private:
  // Counts the work done across passes and reports it through GenerateOptions::progress.
  class Progress;
  Status Setup(std::string* error);
  // Walks the characters [begin, end) every step, counting each step done in *progress.
  Status WalkPass(size_t begin, size_t end, Progress* progress, std::string* error);
  // Walks `passes` passes of `per_pass` characters, in parallel: one pass at a time per thread,
  // each thread with a copy of this generator. Returns the failure of the first pass that failed.
  Status WalkPassesInParallel(size_t passes, size_t per_pass, Progress* progress,
                              std::string* error);
  // 1. The start's sample: where `start` snaps, or, when it may move and the character cannot
  //    stand there, the nearest candidate around it where it can (GenerateOptions).
  Status FindStart(const Vec3& start, bool may_move, Foothold* first, std::string* error);
  // A given start whose nearest sample `*first` lies more than a step across world up from
  // it: the ground on the line through it along world up, found by snapping the line's point
  // at the sample's height until the sample stays (a start at y = 0 under a DEM's hills snapped
  // to the lowest bank nearby, 17 m aside). *first becomes that ground when it lies within a
  // step of the line; true then.
  bool GroundAlongUp(const Vec3& start, Foothold* first, std::string* error, Status* status);
  // The longest step_length with which every foot of a character walking straight on level
  // ground stays within reach of the body (the step vector's reach limit of 7 leaves full
  // steps alone); infinite when any length does (a single gait group). [Units: wu]
  double LongestStepInReach() const;
  // How far from the body the farthest foot's mid key lies on level ground.
  double MidKeyDistance() const;
  // Setup's notes on a character file that walks badly without a word: mid keys out of reach,
  // rests off the ground plane (a Z-up rig), feet resting nearly together.
  void AddCharacterShapeNotes();
  // Setup's note on a terrain whose size or sample spacing is far off the character's step (most
  // likely centimetres against metres: GenerateInputNames::scale).
  void AddUnitsNote(const GridStats& g);
  // 2. The heading at a start whose up is up0: GenerateOptions::heading projected across it.
  Vec3 StartHeading(const Vec3& up0) const {
    return TangentForward(o_.heading, AnyPerpendicular(world_up_), world_up_, up0);
  }
  // 2. Stands a on `ground` in the start's frame (up0, fwd0): its up and its heading, turned
  //    toward its path's first waypoint beyond that waypoint's radius when it has one.
  void Orient(Agent& a, const Foothold& ground, const Vec3& up0, const Vec3& fwd0) const;
  // 3-4. Plants a's feet on `feet`, the snaps of their rest positions (Place), and moves its
  //    frame and ground to them. Returns why a foot cannot stand there, or "".
  std::string Plant(Agent& a, const Foothold* feet) const;
  // 3. Feet of one character that snapped onto one sample (a terrain coarser than the stance,
  //    the start on a sample between two rests): each but the one nearest it snaps again from
  //    the far side of its rest, and takes that sample when no other foot has it and it lies
  //    within a sample spacing as near its rest, and, for an upright character, one it may
  //    stand on (not a riser beyond the rest). (On a beam narrower than the stance the far side
  //    gives the same sample: they share it.) `places` are the rest positions of `total`
  //    feet, `count` a character, `feet` their snaps, updated.
  Status SeparateSharedFeet(const Vec3* places, Foothold* feet, size_t total, size_t count,
                            std::string* error);
  // 3. A character with a foot_length: each foot whose sole, along its character's heading
  //    on its ground, has no ground of its own under its heel or toe (past a stair's nose,
  //    into a riser) moves back or forward by eighths of the sole, up to half of it, to the
  //    nearest place where it has, on a sample no other foot of its character has (two
  //    batches of snaps); it stays where none fits. `feet`, `total`, `count` as for
  //    SeparateSharedFeet; `agents` the characters in order.
  Status FitStartSoles(Foothold* feet, size_t total, size_t count, const Agent* agents,
                       std::string* error);
  // FitSoleWidths on the start feet FitStartSoles checked (`checked`, their soles' directions
  // `forward`), each onto a sample no other foot of its character stands on.
  Status FitStartSoleWidths(Foothold* feet, size_t count, const std::vector<size_t>& checked,
                            const std::vector<Vec3>& forward, std::string* error);
  // 3. Feet whose nearest sample faces away from their character's up: on the inside of a
  //    pipe (a concave surface) the rests laid on the start's tangent plane fall outside the
  //    inner face, nearer a thin wall's outer face, where the character then hung upside down.
  //    Each snaps again from its rest lifted along the up, twice as far each time up to `reach`,
  //    and takes the first sample facing the up. So does a foot whose sample leans more than
  //    max_slope_deg from the up (a riser its rest lies against, where the walk stopped at
  //    once; a multiped's up is the start's normal), moved out along that face across the up
  //    instead, taking the first sample it may stand on. `places`, `total`, `count` and `feet` as
  //    for SeparateSharedFeet; `agents` the characters in order.
  Status SnapFeetFacingUp(const Vec3* places, Foothold* feet, size_t total, size_t count,
                          const Agent* agents, std::string* error);
  // For each of the n crowd starts (places on the grid, and their snaps), another start nearer
  // than `apart` that keeps it out, or -1. Starts that snapped nearer their places keep out
  // those that moved farther (then those earlier in the grid the later); a start kept out keeps
  // no other out.
  static std::vector<int> CrowdedStarts(const Vec3* places, const Foothold* starts, int n,
                                        double apart);
  Status Step(int k, std::string* error);
  // 6 (bipeds). A central locator snapped back toward the body onto ground no lower than the
  // feet's (the nose of the tread they stand on, the place over the tread below) takes the
  // first ground down from it instead: points down kLandLines lines along the up, from the
  // snap to the place, are snapped (one batch); of the ground found straight below them, the
  // highest, as near the place as it reaches, replaces the snap in answers_, when the place's
  // line has ground too or is in the air down to it (over a tread more than max_rise below).
  Status LandLocators(std::string* error);
  // Snaps land_points_ into land_answers_ (one batch), for Land/ClimbLocators.
  Status SnapLandPoints(std::string* error);
  // 6 (bipeds). A central locator snapped onto a face past max_slope_deg facing back along the
  // heading (a riser taller than lead/2 ahead: stairs steeper than the character's stride)
  // takes the ground on top of it instead, when that lies no more than max_rise above the
  // place's rest height, else the tread at its foot, when that lies above the rest height:
  // points up a line inside the face and down a line before it (kClimbDepth sole lengths, or a
  // sample spacing, from it) are snapped (one batch), and the first ground found straight over
  // a point replaces the snap in answers_.
  Status ClimbLocators(std::string* error);
  // True when a biped's locator placed at `placed` snapped (h) onto a tread higher than its
  // rest, aside of its place across a's heading (by `off`, on ground leaning `lean` across it)
  // and little along it: the next tread's nose beside the heading. It then keeps its place
  // across the heading.
  bool ClimbedAside(const Foothold& h, const Vec3& placed, const Agent& a, double lean,
                    double off) const;
  Status QueryFootholds(std::string* error);
  // Accepts the answer h to mv's foothold query, or records why it is refused.
  void Judge(Move& mv, const Foothold& h) const;
  // 8 (end). For the characters whose moves all have a foothold (all_done_), when the character
  // has a foot_length: each foothold whose sole, along the heading on its ground, has no ground
  // of its own under its heel or toe (past a stair's nose, into a riser) moves back or forward
  // along that ground by eighths of the sole, up to half of it, to the nearest place where it
  // has (two batches of snaps); kept as found where none fits or would be refused, and at a
  // wall's foot. A foothold at the edge of the ground the foot stands on, its toe over the drop,
  // is asked again aimed down (the first of the aimed-down tries) and kept for StandAtEdge.
  Status FitSoles(std::string* error);
  // Snaps `points` into `answers` (one batch), for the sole fits.
  Status SnapSole(const std::vector<Vec3>& points, std::vector<Foothold>* answers,
                  std::string* error);
  // 3 and 8 (end). A character with a foot_width: each foothold `holds[i]` (its sole's
  // direction forward[i], non-zero) with no ground of its own under one side of its sole
  // (across the sole at its middle: a side edge) moves toward its other side by eighths of
  // the width, up to half of it, to the nearest place whose sample keeps(i, sample) accepts
  // with ground under the heel, toe and both sides of a sole around that sample (three batches
  // of snaps); it stays where none fits (ground narrower than the sole).
  Status FitSoleWidths(std::vector<Foothold>* holds, const std::vector<Vec3>& forward,
                       const std::function<bool(size_t, const Foothold&)>& keeps,
                       std::string* error);
  // Whether FitSoles may move mv's foothold to h: Judge would accept it as it did the foothold
  // (rise, slope, no nearer its mate across the heading than the lined-up limit or than the
  // foothold), and it keeps at least half the foothold's way `way` along the sole direction f
  // from where the foot stands.
  bool KeepsSoleShift(const Move& mv, const Foothold& h, const Vec3& f, double way) const;
  // FitSoleWidths on the footholds FitSoles checked that stand.
  Status FitMoveSoleWidths(std::string* error);
  // The gap across the heading between the foothold p of mv's foot and its mate (mate_), as a
  // share of their rest gap (1 as at rest, below 0 crossed); 1 for a foot without a mate.
  double GapToMate(const Move& mv, const Vec3& p) const;
  // Judge's side test: true when the accepted foothold p may stand (kept, or kept as the
  // better of a lined-up first answer and its outward retry); false when it is asked again,
  // aimed outward.
  bool KeepsSide(Move& mv, const Vec3& p, const Vec3& normal) const;
  // The reach limit for one character whose moves moves_[m, e) all have a foothold: refuses
  // the footholds beyond reach of the body they lead to, or all of them when a planted foot
  // would be left beyond reach.
  void CheckReach(size_t m, size_t e);
  // 7 (end). For one character whose moves are moves_[m, e), once each step still to be asked
  // has its vector: shortens those steps, all alike, to the longest that keeps each of their
  // feet within reach of the body the group's steps move together (and, when every other group
  // has waited in a row, so that a hold now would end the walk, each planted foot too), then
  // aims the last retries down. A foot already beyond reach before the step does not count.
  // (Each step was held to reach against the body moved by its own share alone: steps of a
  // group, whose other feet move the body too, were cut that needed no cut, and a hind foot's
  // long step carried the body away from the other hind foot.)
  void FitInReach(size_t m, size_t e);
  // Whether a refusal (a gap or not) becomes mv's reason (see Move::reason).
  static bool KeepsReason(const Move& mv, bool gap) {
    return mv.reason.empty() || (mv.reason_is_gap && !gap);
  }
  // 8 (end). A foot whose tries to step down past the edge it had reached (Move::at_edge) were
  // all refused stands at that edge (true).
  static bool StandAtEdge(Move& mv);
  // 8 (end). A foot refused every foothold toward a target behind it along the heading (a hind
  // foot standing at a terrain's back edge, ahead of its rest), or while its character turns at
  // a short stride (a foot on a stair's nose turning on the spot), keeps its place: a step in
  // place, so its group waits for the body to move on or turn rather than stop the walk.
  void KeepPlace(Move& mv) const;
  // Gives up on mv's foothold after its last try; its reason says how many were refused.
  static void Fail(Move& mv);
  Status ClearArcs(int k, std::string* error);
  // Keys (or stops) the w-th walking character at step k once its moves are final.
  void Finish(size_t w, int k);
  // The frame at which step k (from 0) starts, and step k - 1 ends: the same double wherever
  // it is asked for, so that a touch-down and the next lift-off, or a body key and its step's
  // foot keys, never differ by a rounding (a fractional start frame drifted them apart).
  double StepFrame(double k) const { return o_.start_frame + k * c_.frames_per_step; }
  int window_steps_ = 100;  // steps a body must get half a step in (Agent::window_from)
  // fn(begin, end) over [0, count), split across the pool's threads for large counts. Each
  // item's result must not depend on the split.
  template <typename Fn>
  void Parallel(size_t count, Fn&& fn) {
    if (threads_ <= 1 || count < kMinParallel) return fn(size_t{0}, count);
    if (!pool_) pool_ = SharedBatchPool(threads_);  // the engine's threads, on first use
    // Chunks of about count / (8 threads), taken in turn: a thread the system holds up delays
    // the others little.
    const size_t chunk = std::max<size_t>(1, count / (8 * static_cast<size_t>(threads_)));
    pool_->Run(count, chunk, fn);
  }
  // 5. Turns a's heading toward its current waypoint (at most max_turn_deg, and no farther
  // than keeps every pair's feet apart across it when gait group `group` steps next) and sets
  // a's stride; marks a arrived at the last waypoint.
  void Steer(Agent& a, int group) const;
  // The share of a full stride a body heading `forward` takes toward a waypoint `to` away along
  // the ground, reached within `radius`: below 1 for a waypoint inside the circle it turns on at
  // full stride, unless the heading passes within `radius` of it.
  double StrideToward(const Vec3& to, const Vec3& forward, double radius) const;
  // The least gap across the heading between a foot and its mate (mate_), as a share of their
  // gap at rest, once a heading `forward` at `stride` has been taken and gait group `group` has
  // stepped (each of its feet at most step_length toward its target on ground as level as a's):
  // below 0 when feet cross.
  double PairGap(const Agent& a, const Vec3& forward, double stride, int group) const;
  // The radius within which a's waypoint i counts as reached: half a step for the last, a
  // step for the others.
  double Radius(const Agent& a, size_t i) const;
  // Whether a's waypoint i lies on the terrain: within half its radius of a sample.
  bool OnTerrain(const Agent& a, size_t i) const;
  // Whether a's waypoint i counts as reached, within its radius of a's ground: along the ground,
  // whatever the waypoint's height above or below it (a biped's waypoint in the air), unless
  // the waypoint lies on the terrain farther than the radius along a's up: the far side of a
  // sphere, a floor under a table top, a ceiling.
  bool Reached(const Agent& a, size_t i) const;
  // Whether a's body has reached its path's goal, every waypoint from its current one on
  // reached in turn (the last step's arrival, which no later step has looked at yet).
  bool Arrived(const Agent& a) const {
    size_t next = a.waypoint;
    while (next < a.path.size() && Reached(a, next)) ++next;
    return next == a.path.size();
  }
  // How far a's waypoint i still is, as Reached measures it: in 3D when it lies on the terrain,
  // else along the ground (level on a floor: across the world up, whatever a's up leans).
  double Remaining(const Agent& a, size_t i) const;
  // How far a's path goes on from where it stands: to its waypoint, then leg after leg to the
  // goal. [Units: wu]
  double PathLeft(const Agent& a) const;
  // "D away" for a path walk short of its goal: along the path when legs are left ("D away
  // along the path (S in a straight line)": the straight line alone misled by kilometres).
  std::string HowFar(const Agent& a) const;
  // The offset from a's ground to a point `p` of its path, as the walk aims at it: with p's
  // height along the world up taken off while a stands on ground facing up (within
  // kFloorUpDeg of the world up), unless p lies on the terrain (`on_terrain`): a path given at
  // any height, a 2D path at y = 0 over a DEM 537 m up, is followed across the ground by
  // multipeds too, whose up leans with the ground (on a 15-degree slope a goal 5 m up was
  // reached a metre past it). On walls and ceilings the height is along a's up.
  Vec3 ToPathPoint(const Agent& a, const Vec3& p, bool on_terrain) const;
  // Whether a stands on ground facing the world up (within kFloorUpDeg of it): path heights
  // are then taken along the world up.
  bool OnFloor(const Agent& a) const;
  // `to`, an offset from ToPathPoint (to a waypoint `on_terrain` or not), laid onto a's
  // ground (the plane across a.up), to steer by. While a stands on a floor (OnFloor), straight
  // along the world up, so that seen from above it points where the waypoint lies (laid along
  // a's up, it turned toward the contour wherever the ground leaned: multipeds walked a 2D path
  // up to 33 degrees off its line, and bowed 1.3 m off a 32 m line to a goal on a DEM), for a
  // waypoint off the terrain (a level `to`) or one on it farther than 10 steps and within 30
  // degrees of the level. Else, near a waypoint on the terrain (the foot of a riser) or steeply
  // above or below (the far side of a sphere, reached around the surface), and on walls and
  // ceilings, along a's up.
  Vec3 OnGround(const Agent& a, const Vec3& to, bool on_terrain) const;
  Vec3 ToWaypoint(const Agent& a, size_t i) const {
    return ToPathPoint(a, a.path[i], OnTerrain(a, i));
  }
  // At step k: false once a has come no nearer (Agent::nearest) to its current waypoint for
  // window_steps_ steps.
  bool Nearing(Agent& a, int k) const;
  Vec3 Left(const Agent& a) const { return Cross(a.up, a.forward); }
  Vec3 Place(const Agent& a, const Vec3& rest) const {
    return a.ground + Left(a) * rest.x + a.up * rest.y + a.forward * rest.z;
  }
  // World up for bipeds, else the feet's averaged normal (`previous` when they cancel).
  Vec3 AveragedUp(const Vec3& previous, const std::vector<Vec3>& normals) const;
  // The up of the feet's frame, in which steps are aimed and footholds judged, for feet at
  // `feet` on ground of `normals`: world up for bipeds, else halfway between their averaged
  // normal and BodyUp (on stairs, between a tread's and the flight's, so steps lead up or down
  // the flight rather than into its risers).
  Vec3 FeetUp(const Vec3& previous, const std::vector<Vec3>& feet,
              const std::vector<Vec3>& normals) const;
  // The body's up over feet standing at `feet`: world up for bipeds; for multipeds the normal
  // of the plane fitted to the feet, the terrain's at the body's scale (on stairs the flight's,
  // not a tread's or a riser's), on the side of `feet_up`, which it falls back to for feet in a
  // line or a plane leaning more than 60 degrees from it.
  Vec3 BodyUp(const Vec3& feet_up, const std::vector<Vec3>& feet) const;
  // The body's up after a step: halfway between the plane fitted to the feet before it
  // (`before`) and after it (`after`), as long as they lie within 90 degrees of each other,
  // else `after`. A diagonal gait's feet, fitted one phase at a time on curved ground, lean
  // the plane to one side and then the other: a trotting quadruped's body rocked 8 to 10
  // degrees each step down a sphere or over a ramp's change of slope, where the fits of two
  // phases in a row lean as much either way.
  static Vec3 GaitCycleUp(const Vec3& before, const Vec3& after);
  void KeyFoot(const Agent& a, int foot, double frame, KeyPhase phase, const Vec3& p,
               const Vec3& n);
  // Keys a's body at `frame`, `raise` above its place along its up.
  void KeyBody(const Agent& a, double frame, double raise);
  // Keys the bodies in body_due_ (agent, frame), each raised where the terrain comes nearer
  // than kBodyClearance (a body over a block's edge as the feet wrap around it, a ridge between
  // the feet); their points are snapped in one batch per round. Empties body_due_.
  Status KeyBodies(std::string* error);
  // The most `a`'s body may rise along its up with every foot still within reach, and at most
  // kBodyRounds body heights.
  double MaxBodyRaise(const Agent& a) const;
  // Keys a's feet where they stand at the start frame, and asks for its body (body_due_).
  void KeyStart(const Agent& a);
  void Stop(Agent& a, int step, const std::string& why);
  // Takes back the foot keys of a step that started at frame f0 (its body not yet keyed).
  void UnkeyStep(const Agent& a, double f0);
  // A call that failed during step k (footfalld gone): every character of the pass still
  // walking stops at that step with `why`, its keys of the step taken back, body's too.
  void StopPassAt(int k, const std::string& why);
  // A failed batch call: the session's status, and its message prefixed with `what`.
  Status Check(Status status, const char* what, std::string* error) {
    if (status != Status::kOk) *error = std::string(what) + ": " + session_.last_error();
    return status;
  }

  TerrainSession& session_;
  TerrainHandle terrain_;
  const Character& c_;
  const GenerateOptions& o_;
  Walk& walk_;
  std::vector<Agent>& agents_;
  int threads_;  // for Parallel; 1 in the copies that walk passes in parallel
  Vec3 world_up_;
  int steps_ = 0;
  double lead_ = 0;
  // The radius of the circle the body turns on at full stride and max_turn_deg a step (its
  // ground moves step_length over the number of gait groups a step).
  double turn_radius_ = 0;
  // The farthest a point of the surface may be from its nearest sample, estimated from the
  // grid: twice its sample spacing (GridStats::spacing). [Units: wu]
  double gap_ = 0;
  Vec3 bounds_min_, bounds_max_;  // the terrain's samples' bounds
  // cos(max_slope_deg), sin(slope_threshold_deg): slope tests on dot products of unit vectors.
  double cos_max_slope_ = -1, sin_slope_threshold_ = 1;
  size_t pass_begin_ = 0, pass_end_ = 0;  // the agents walking in this pass
  // One pass walks every character: a call failing after the first step stops the walk there,
  // its keys so far kept (with several passes, later ones would have no keys at all).
  bool keep_on_failure_ = false;
  // What the set-up found worth saying of the whole walk (a start far from the terrain, steps
  // longer than the reach allows): the first of Walk::notes.
  std::vector<std::string> setup_notes_;
  // The first foot keyed at the start beyond reach of its body (snapped to samples too far
  // apart for the character), said as a note: "" when none was. It is the first character's
  // with such a foot (start_beyond_reach_agent_, in agents_), whichever pass walked it.
  std::string start_beyond_reach_;
  size_t start_beyond_reach_agent_ = std::numeric_limits<size_t>::max();
  // The start's nearest sample (FindStart's first snap, before the start may move), or the
  // ground straight above or below a given start (GroundAlongUp).
  Foothold start_snap_;
  bool start_along_up_ = false;  // start_snap_ is GroundAlongUp's
  std::shared_ptr<BatchPool> pool_;
  std::vector<int> pair_of_foot_;
  // Each foot's other foot across the body, whose side it keeps to (PairGap, GapToMate): its
  // pair's other foot, or for a foot paired with none the foot on the other side whose rest
  // lies nearest its own mirrored across the body; -1 for none (a foot on the centre line).
  std::vector<int> mate_;
  std::vector<Vec3> rest_;         // each foot's rest less RestCentroid, character space
  std::vector<Vec3> pair_centre_;  // rest centre of each pair, as rest_
  std::vector<std::vector<int>> pairs_of_group_;  // pairs with a foot in each gait group
  // slot_of_foot_[g][j]: index in pairs_of_group_[g] of the pair of foot gait[g][j]
  std::vector<std::vector<size_t>> slot_of_foot_;
  // move_of_foot_[g][f]: j when foot f is gait[g][j] (its move is the j-th of its character's
  // moves in a step of group g), else -1
  std::vector<std::vector<int>> move_of_foot_;
  // Buffers reused every step. The moves of the w-th walking character of a step are
  // moves_[w * G .. (w + 1) * G) for G feet in the stepping group.
  std::vector<size_t> walking_;  // agents walking this step
  std::vector<size_t> walkers_;  // indices in walking_ of the characters placing feet this pass
  std::vector<char> retry_;      // per walking character: a foot to place again
  std::vector<Move> moves_;
  std::vector<Vec3> locator_, locator_normal_;  // per move
  std::vector<size_t> pending_, still_;
  std::vector<char> verdict_, raised_;
  // A character in a round of arc checks: the w-th walking one, its arcs pending_[begin, end).
  struct ArcAgent {
    size_t walking, begin, end;
  };
  std::vector<ArcAgent> arc_agents_, next_agents_;
  int group_ = 0;  // the gait group stepping now
  // Query points and answers of each round, one buffer per kind of round so that their sizes
  // stay the same from step to step (no refill on resize).
  std::vector<Vec3> points_, arc_points_;  // setup and locators; arc check points
  std::vector<size_t> arc_first_;          // per pending move: its first arc check point
  std::vector<Vec3> land_points_;          // LandLocators: points down the lines
  std::vector<Foothold> land_answers_;
  std::vector<size_t> land_locator_;  // per locator probed: its index into points_
  std::vector<size_t> land_first_;    // ClimbLocators: each probed locator's first point
  std::vector<char> landed_;          // per locator: 1 when Land/ClimbLocators replaced its snap
  std::vector<StepQuery> queries_;
  std::vector<char> all_done_;  // per walker of a round: every move has a foothold (CheckReach)
  // FitSoles: the moves checked (and their walkers), the ways each may move, and the first of
  // each one's candidates' snap points (centre, heel, toe; after the heel, toe and raised toe of
  // every move checked, in the first batch).
  std::vector<size_t> sole_moves_, sole_walker_, sole_first_;  // (sole_walker_: in walkers_)
  std::vector<int> sole_ways_;  // (0: its sole fits, or it stays as found)
  std::vector<Vec3> sole_points_;
  std::vector<Foothold> sole_answers_;
  std::vector<Foothold> answers_, next_answers_, arc_answers_;
  // Bodies to key (KeyBodies): (agent, frame); per walking character the frame its body is due
  // at this step (NaN: none).
  std::vector<std::pair<size_t, double>> body_due_;
  std::vector<double> body_frame_, body_raise_;
  std::vector<size_t> body_pending_, body_still_;
  std::vector<Vec3> body_points_;
  std::vector<size_t> spine_first_;  // per due body: its first spine point (KeyBodies)
};

}  // namespace footfall::steps_detail
