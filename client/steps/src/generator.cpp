// The step generator. The numbered comments match the numbered list of "The algorithm" in the
// top-level README.md.
#include "footfall/steps/generator.h"
#include "footfall/terrain/batch_pool.h"
#include "footfall/terrain/shown_text.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <unordered_map>

#include "frame_math.h"
#include "key_arena.h"

namespace footfall {
namespace {

using namespace steps_detail;

// Foothold queries per foot and step, in turn: the step vector scaled (shorter, then longer:
// over a stair's riser, then shorter still), then aimed down by `drop` times max_rise along the
// body's up (down a stair's nose, or over a convex edge onto the face below it).
struct Attempt {
  double scale, drop;
};
constexpr int kMaxAttempts = 7;
constexpr Attempt kAttempts[kMaxAttempts] = {{1.0, 0},   {0.6, 0},   {1.35, 0}, {0.3, 0},
                                             {1.0, 0.5}, {0.6, 0.5}, {0.3, 0.5}};
// A foothold is looked for within this fraction of step_length of where the foot aims.
constexpr double kFootholdTolerance = 0.5;
constexpr int kMaxRaises = 8;         // swing arc raises before giving up
constexpr double kRaise = 0.5;        // raise per round, in step heights
constexpr double kSlide = 0.25;       // slide per round toward a blocked half's end (of the way)
constexpr double kAlikeCos = 0.7071;  // footholds whose normals are within 45 deg face alike
// A body key keeps at least this fraction of body_height from the terrain (measured as arcs
// are, from its nearest sample); nearer, it is raised along its up, in up to kBodyRounds rounds
// of at most body_height each, and never beyond reach of a foot.
constexpr double kBodyClearance = 0.5;
constexpr int kBodyRounds = 3;
// Room for an upright body (bipeds): points of its spine, from half body_height above the
// feet's centroid up to the body, at most this many and no farther apart than the terrain's
// gap, are snapped; a nearest sample on the spine's line (within the gap), above every foot by
// more than the gap and below the body is terrain between the feet and the body, and the walk
// stops before that step (a biped walking under a slab lower than its body had its feet under
// it and its body over it). Not tried for multipeds, whose bodies lean with the terrain and
// whose feet wrap around edges.
constexpr size_t kMaxSpineChecks = 17;
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
constexpr size_t kMinArcChecks = 7;
constexpr size_t kMaxArcChecks = 63;

// The number of points checked along an arc of `length` (its longer half twice), no farther
// apart than `gap`: 7, 15, 23, ... 63, so that the seven points of the shortest arcs (at
// eighths) are always among them.
// [Units: length, gap in wu]
size_t ArcChecks(double length, double gap) {
  static_assert((kMaxArcChecks + 1) % 8 == 0 && (kMinArcChecks + 1) == 8, "checks at eighths");
  if (!(gap > 0) || !std::isfinite(length)) return kMinArcChecks;
  const double eighths = std::ceil(length / gap / 8);
  constexpr double kMost = (kMaxArcChecks + 1) / 8.0;
  return 8 * static_cast<size_t>(eighths > 1 ? std::min(eighths, kMost) : 1.0) - 1;
}

// The j-th of an arc's `checks` points, as a fraction of the arc (0: its start key, 0.5: its
// mid key, 1: its end key).
double ArcS(size_t j, size_t checks) {
  return static_cast<double>(j + 1) / static_cast<double>(checks + 1);
}
// Required clearance at each check point, as a fraction of the arc's nominal clearance there
// (the step height at the mid key, falling linearly to 0 at the start and end keys).
constexpr double kClearanceFraction = 0.25;
// Steer: a turn is tried at its whole and then in kTurnShares - 1 smaller shares, and the
// largest that keeps every pair's feet at least kMinPairGap of their rest gap apart is taken.
constexpr int kTurnShares = 8;
// Ground whose up lies within this many degrees of the world up is a floor for path walks:
// waypoints off the terrain are aimed at across it, their height along the world up ignored.
constexpr double kFloorUpDeg = 60;
constexpr double kMinPairGap = 0.5;
// A step shorter than this fraction of step_length is a step in place: no foothold query.
constexpr double kInPlace = 0.02;
// Move::query of a move not asked this round.
constexpr size_t kNoQuery = ~size_t{0};
// Per-character loops split across threads only from this many items (a hand-over costs
// ~20 us).
constexpr size_t kMinParallel = 512;

// The distance from p to the box [lo, hi] (0 inside).
double BoxDistance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 out{std::max({lo.x - p.x, 0.0, p.x - hi.x}), std::max({lo.y - p.y, 0.0, p.y - hi.y}),
                 std::max({lo.z - p.z, 0.0, p.z - hi.z})};
  return Length(out);
}

// `value` to 3 significant digits, or to as many more as it takes to differ from `limit`, which
// it breaks: "leans 100.0001 deg, more than max_slope_deg 100", never "leans 100 ... 100".
std::string Beyond(double value, double limit) {
  for (int digits = 3;; ++digits) {
    std::ostringstream a, b;
    a.precision(digits), b.precision(digits);
    a << value, b << limit;
    if (a.str() != b.str() || digits >= 17) return a.str();
  }
}

std::string Point(const Vec3& p) {
  std::ostringstream o;
  o.precision(4);
  o << std::fixed << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return o.str();
}

// For ground facing away from the character's up (more than 120 degrees): what would make it
// so where the ground should face up (an underside is often just that: a log's, a beam's).
std::string FacingDownHint(double slope_deg) {
  if (!(slope_deg > 120)) return "";
  return "; it faces down: if the ground there should face up, the surface may be thinner than "
         "the terrain's sample spacing (resample at a separation below its thickness) or a "
         "mesh's faces may face inward";
}

// How far p is above the terrain, from h, the sample nearest to it: its height along h's
// normal (negative: below the terrain), or, when larger, its distance to h less `gap`, the
// farthest the surface may be from its nearest sample. No sample is nearer than h, so no
// surface is nearer than that: above a stair's nose, whose nearest sample may be the riser's
// top, a point high up is in the clear although it lies little in front of the riser's plane.
// Behind h's plane, p is below only within `gap` of h along the plane or not above h along
// `up`, the character's: farther and above, the plane is not the surface there (p high above a
// nose, just behind its riser's plane, is in the clear; a point under a surface has a nearest
// sample nearly straight above it). Dense arc checks put points there: a 3 m stride down
// stairs stopped at its second step. [Units: gap in wu]
double Clearance(const Vec3& p, const Foothold& h, double gap, const Vec3& up) {
  const Vec3 v = p - h.point;
  const double height = Dot(v, h.normal);
  if (height <= 0 && (Length2(v) - height * height <= gap * gap || Dot(v, up) <= 0)) return height;
  return std::max(height, Length(v) - gap);
}

// The clearance an arc point must keep from h, its nearest sample: `nominal`, or, when the
// foothold `foot` at that end of the arc stands against h's face (in front of its plane, nearer
// than `near`, on ground unlike it: a toe at a riser), no more than half of what the foot itself
// keeps from that plane.
double ClearanceNeeded(double nominal, const Foothold& h, const Vec3& foot, const Vec3& foot_normal,
                       double near) {
  const double kept = Dot(foot - h.point, h.normal);
  if (Dot(h.normal, foot_normal) >= kAlikeCos || kept < 0 || kept > near) return nominal;
  return std::min(nominal, 0.5 * kept);
}

// One walking character.
struct Agent {
  std::string id;                       // "" for a single character, else "c1".."cN"
  bool left_out = false;                // a crowd's character starting on another: no tracks
  Vec3 ground;                          // the body's ground point: centroid of the planted feet
  Vec3 up;                              // the up of the feet's frame (FeetUp)
  Vec3 body_up;                         // the body's up (BodyUp)
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
  int nearest_step = 0;
  // This step's stride, as a share of a full one (Steer): below 1 while the waypoint lies inside
  // the circle the body turns on at full stride, 0 to turn on the spot.
  double stride = 1;
  bool walking = true;  // false once stopped or arrived
  int waits = 0;        // steps in a row its group stepped in place, waiting for a planted foot
  int still = 0;        // steps in a row no foot of it moved (waits, turns on the spot included)
  // Where the body was at step `window_step`: a body that stays within half a step of it for
  // Generator::window_steps_ steps is milling about at a dead end (`window_left`: it has been
  // farther since, as a walk along a loop that comes back there is).
  Vec3 window_from;
  int window_step = -1;
  bool window_left = false;
  std::string stopped;   // why it stopped early ("" when it did not)
  int stopped_step = 0;  // the step it stopped at
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
  Vec3 ideal;               // the last query's ideal point
  Vec3 step;                // the last query's step vector
  size_t query = kNoQuery;  // index of this round's foothold answer, or kNoQuery
  // A foothold accepted but lined up with (or across) its pair's other foot, samples lying
  // about as far apart as the feet: the query is asked again aimed outward (`outward`), and
  // this one (`lined_up`, its gap as a share of the rest gap) is kept unless that does better.
  bool outward = false;
  bool lined_up = false;
  double lined_up_gap = 0;
  Vec3 lined_up_point, lined_up_normal;
};

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
  //    within a sample spacing as near its rest. (On a beam narrower than the stance the far
  //    side gives the same sample: they share it.) `places` are the rest positions of `total`
  //    feet, `count` a character, `feet` their snaps, updated.
  Status SeparateSharedFeet(const Vec3* places, Foothold* feet, size_t total, size_t count,
                            std::string* error);
  // For each of the n crowd starts (places on the grid, and their snaps), another start nearer
  // than `apart` that keeps it out, or -1. Starts that snapped nearer their places keep out
  // those that moved farther (then those earlier in the grid the later); a start kept out keeps
  // no other out.
  static std::vector<int> CrowdedStarts(const Vec3* places, const Foothold* starts, int n,
                                        double apart);
  Status Step(int k, std::string* error);
  Status QueryFootholds(std::string* error);
  // Accepts the answer h to mv's foothold query, or records why it is refused.
  void Judge(Move& mv, const Foothold& h) const;
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
  // Whether a refusal (a gap or not) becomes mv's reason (see Move::reason).
  static bool KeepsReason(const Move& mv, bool gap) {
    return mv.reason.empty() || (mv.reason_is_gap && !gap);
  }
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
  // the ground: below 1 for a waypoint inside the circle it turns on at full stride.
  double StrideToward(const Vec3& to, const Vec3& forward) const;
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
  // How far a's waypoint i still is, as Reached measures it: in 3D when it lies on the terrain,
  // else along the ground.
  double Remaining(const Agent& a, size_t i) const;
  // The offset from a's ground to a point `p` of its path, as the walk aims at it: with p's
  // height along the world up taken off while a stands on ground facing up (within
  // kFloorUpDeg of the world up), unless p lies on the terrain (`on_terrain`): a path given at
  // any height, a 2D path at y = 0 over a DEM 537 m up, is followed across the ground by
  // multipeds too, whose up leans with the ground (on a 15-degree slope a goal 5 m up was
  // reached a metre past it). On walls and ceilings the height is along a's up.
  Vec3 ToPathPoint(const Agent& a, const Vec3& p, bool on_terrain) const;
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
  // grid: twice the mean spacing, cell_size / sqrt(samples per occupied cell). [Units: wu]
  double gap_ = 0;
  Vec3 bounds_min_, bounds_max_;  // the terrain's samples' bounds
  // cos(max_slope_deg), sin(slope_threshold_deg): slope tests on dot products of unit vectors.
  double cos_max_slope_ = -1, sin_slope_threshold_ = 1;
  size_t pass_begin_ = 0, pass_end_ = 0;  // the agents walking in this pass
  // One pass walks every character: a call failing after the first step stops the walk there,
  // its keys so far kept (with several passes, later ones would have no keys at all).
  bool keep_on_failure_ = false;
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
  std::vector<StepQuery> queries_;
  std::vector<Foothold> answers_, next_answers_, arc_answers_;
  // Bodies to key (KeyBodies): (agent, frame); per walking character the frame its body is due
  // at this step (NaN: none).
  std::vector<std::pair<size_t, double>> body_due_;
  std::vector<double> body_frame_, body_raise_;
  std::vector<size_t> body_pending_, body_still_;
  std::vector<Vec3> body_points_;
  std::vector<size_t> spine_first_;  // per due body: its first spine point (KeyBodies)
};

Vec3 Generator::AveragedUp(const Vec3& previous, const std::vector<Vec3>& normals) const {
  if (!c_.align_to_normal) return world_up_;
  Vec3 sum;
  for (const Vec3& n : normals) sum += n;
  return NormalizeOr(sum, previous);
}

Vec3 Generator::FeetUp(const Vec3& previous, const std::vector<Vec3>& feet,
                       const std::vector<Vec3>& normals) const {
  if (!c_.align_to_normal) return world_up_;
  const Vec3 averaged = AveragedUp(previous, normals);
  return NormalizeOr(averaged + BodyUp(averaged, feet), averaged);
}

Vec3 Generator::BodyUp(const Vec3& feet_up, const std::vector<Vec3>& feet) const {
  if (!c_.align_to_normal) return world_up_;
  return FittedPlaneNormal(feet.data(), feet.size(), feet_up);
}

void Generator::KeyFoot(const Agent& a, int foot, double frame, KeyPhase phase, const Vec3& p,
                        const Vec3& n) {
  std::pmr::vector<WalkKey>& keys = walk_.tracks[a.first_track + foot].keys;
  if (!keys.empty() && keys.back().frame == frame) {
    // A foot lifting on the frame it stands at: at the start frame the lift-off replaces the
    // plant; later (a gait of one group, whose feet land and lift on the same frame) the
    // touch-down stays, and the swing starts from it.
    if (frame != o_.start_frame) return;
    keys.pop_back();
  }
  WalkKey key;
  key.frame = frame, key.phase = phase, key.position = p, key.normal = n;
  keys.push_back(key);
}

void Generator::KeyBody(const Agent& a, double frame, double raise) {
  WalkKey key;
  key.frame = frame;
  key.position = a.ground + a.body_up * (c_.body_height + raise);
  key.normal = a.body_up;
  WalkTrack& track = walk_.tracks[a.first_track + c_.feet.size()];
  track.keys.push_back(key);
  const Vec3 forward = TangentForward(a.forward, a.forward, a.up, a.body_up);
  track.rotations.push_back(QuatFromBasis(Cross(a.body_up, forward), a.body_up, forward));
}

void Generator::Stop(Agent& a, int step, const std::string& why) {
  a.walking = false;
  std::ostringstream m;
  m << "step " << step;
  if (!a.id.empty()) m << " of " << a.id;
  m << ": " << why << "; walk stopped, keys up to step " << step - 1 << " kept";
  a.stopped = m.str();
  a.stopped_step = step;
}

bool Generator::Nearing(Agent& a, int k) const {
  if (a.path.empty()) return true;
  const double d = Remaining(a, a.waypoint);
  if (a.nearest_waypoint != a.waypoint || d < a.nearest - 0.25 * c_.step_length) {
    a.nearest_waypoint = a.waypoint, a.nearest = d, a.nearest_step = k;
    return true;
  }
  return k - a.nearest_step < window_steps_;
}

double Generator::Radius(const Agent& a, size_t i) const {
  return (i + 1 == a.path.size() ? 0.5 : 1.0) * c_.step_length;
}

bool Generator::OnTerrain(const Agent& a, size_t i) const {
  return a.path_off[i] <= 0.5 * Radius(a, i);
}

Vec3 Generator::ToPathPoint(const Agent& a, const Vec3& p, bool on_terrain) const {
  Vec3 to = p - a.ground;
  if (!on_terrain && Dot(a.up, world_up_) >= std::cos(Radians(kFloorUpDeg)))
    to -= world_up_ * Dot(to, world_up_);
  return to;
}

double Generator::Remaining(const Agent& a, size_t i) const {
  const Vec3 to = ToWaypoint(a, i);
  return OnTerrain(a, i) ? Length(to) : Length(ProjectOnPlane(to, a.up));
}

bool Generator::Reached(const Agent& a, size_t i) const {
  const Vec3 to = ToWaypoint(a, i);
  const double along = Dot(to, a.up), radius = Radius(a, i);
  if (Length2(to - a.up * along) > radius * radius) return false;
  // On the terrain: no farther below the ground than the radius, nor above it than the radius
  // over the body's height (the feet's centroid lies inside a convex nose or ridge they stand
  // around: an octopod on the Spot mesh's nose came within 2 cm of its goal with its body,
  // never within its radius with its ground, and turned about it until it stopped).
  return !OnTerrain(a, i) || (along >= -radius && along <= radius + c_.body_height);
}

double Generator::StrideToward(const Vec3& to, const Vec3& forward) const {
  // A waypoint inside the circle the body turns on at full stride (beside or behind it, nearer
  // than the turn allows) would be circled for ever: the steps shorten so that the circle the
  // body turns on, tangent to the heading, runs through the waypoint, and with the waypoint
  // behind that heading the character turns on the spot.
  const double ahead = Dot(to, forward);
  const double aside = Length(to - forward * ahead);
  const double through = Length2(to) / (2 * aside);  // that circle's radius (inf: no circle)
  if (through >= turn_radius_) return 1;
  return ahead > 0 ? through / turn_radius_ : 0;
}

double Generator::PairGap(const Agent& a, const Vec3& forward, double stride, int group) const {
  const Vec3 left = Cross(a.up, forward);
  const std::vector<int>& stepping = c_.gait[group];
  // Where each foot stands once the group has stepped: planted feet where they are, stepping
  // ones a step toward their targets.
  thread_local std::vector<Vec3> at;
  at.assign(a.foot.begin(), a.foot.end());
  for (int f : stepping) {
    const Vec3 target = a.ground + left * rest_[f].x + forward * (rest_[f].z + lead_ * stride);
    Vec3 v = ProjectOnPlane(target - a.foot[f], a.up);
    const double len = Length(v);
    if (len > c_.step_length) v = v * (c_.step_length / len);
    at[f] += v;
  }
  double least = std::numeric_limits<double>::infinity();
  for (size_t f = 0; f < at.size(); ++f) {
    const int m = mate_[f];
    if (m >= 0) least = std::min(least, Dot(at[f] - at[m], left) / (rest_[f].x - rest_[m].x));
  }
  return least;
}

void Generator::Steer(Agent& a, int group) const {
  if (a.path.empty()) return;
  while (a.waypoint < a.path.size() && Reached(a, a.waypoint)) ++a.waypoint;
  if (a.waypoint == a.path.size()) {
    a.walking = false;  // arrived: not an early stop
    return;
  }
  const Vec3 to = ProjectOnPlane(ToWaypoint(a, a.waypoint), a.up);
  a.stride = 1;
  // A waypoint on the terrain straight above or below (the far side of a sphere): any way on
  // along the ground leads toward it, so the heading is kept until it lies farther aside.
  if (Length(to) <= Radius(a, a.waypoint)) return;
  const Vec3 want = Normalize(to);
  const double angle = std::atan2(Dot(Cross(a.forward, want), a.up), Dot(a.forward, want));
  const double max_turn = Radians(c_.max_turn_deg);
  const double turn = std::clamp(angle, -max_turn, max_turn);
  // A turn faster than the feet can follow (a foot moves at most step_length a step, and only
  // in its group's turn) leaves the planted feet behind, until a pair's feet cross under the
  // body: the turn is cut to the largest share of it (in eighths) that keeps every pair's feet
  // at least half their rest gap apart, or failing that to the one keeping them farthest apart.
  // Feet that have not moved for a whole gait cycle will not catch up by waiting: the whole
  // turn is taken, so that the targets it gives may find footholds.
  if (a.still >= static_cast<int>(c_.gait.size())) {
    a.forward = Normalize(RotateAround(a.forward, a.up, turn));
    a.stride = StrideToward(to, a.forward);
    return;
  }
  double best_gap = -std::numeric_limits<double>::infinity();
  Vec3 best_forward = a.forward;
  double best_stride = 1;
  for (int eighths = kTurnShares; eighths >= 0; --eighths) {
    const Vec3 forward = Normalize(RotateAround(a.forward, a.up, turn * eighths / kTurnShares));
    const double stride = StrideToward(to, forward);
    const double gap = PairGap(a, forward, stride, group);
    if (gap > best_gap) best_gap = gap, best_forward = forward, best_stride = stride;
    if (gap >= kMinPairGap) {
      best_forward = forward, best_stride = stride;
      break;
    }
  }
  a.forward = best_forward, a.stride = best_stride;
}

class Generator::Progress {
 public:
  // `total` units of work, reported scaled down to fit an int.
  Progress(const std::function<void(int, int)>& report, int64_t total)
      : report_(report),
        total_(total),
        scale_(total > INT_MAX ? static_cast<double>(INT_MAX) / static_cast<double>(total) : 1.0) {}
  void Add(int64_t work) {
    if (!report_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    done_ += work;
    report_(static_cast<int>(static_cast<double>(done_) * scale_),
            static_cast<int>(static_cast<double>(total_) * scale_));
  }

 private:
  const std::function<void(int, int)>& report_;
  const int64_t total_;
  const double scale_;
  std::mutex mutex_;
  int64_t done_ = 0;
};

Status Generator::Run(std::string* error) {
  world_up_ = Normalize(o_.up);
  const int groups = static_cast<int>(c_.gait.size());
  steps_ = o_.steps >= 0 ? o_.steps : (o_.path.empty() ? kDefaultSteps : kMaxPathSteps);
  // Far longer than any stall of a walk that goes on (characters turning about a waypoint on
  // stairs stood within half a step for 32 steps, then walked on): 100 steps, 16 gait cycles,
  // or a whole turn at max_turn_deg and four cycles, whichever is longest. (A goal just behind
  // a character that turns 1 degree a step is neared again only most of a circle later.)
  window_steps_ =
      std::max({100, 16 * groups,
                static_cast<int>(std::min(1000.0, std::ceil(360 / c_.max_turn_deg))) + 4 * groups});
  // The target locator's lead over the foot's rest position: with the body at the feet's
  // centroid, L * (G + 1) / (2G) makes every foot travel exactly L per step once walking
  // (half a step ahead for G -> infinity; 3/4 of a step for two gait groups).
  lead_ = c_.step_length * (groups + 1) / (2.0 * groups);
  turn_radius_ = c_.step_length / groups / (2 * std::sin(0.5 * Radians(c_.max_turn_deg)));
  // (Past the ends of their ranges the tests hold or fail whatever the rounding of the dots.)
  cos_max_slope_ =
      c_.max_slope_deg >= 180 ? -2.0 : std::cos(Radians(std::max(c_.max_slope_deg, 0.0)));
  sin_slope_threshold_ =
      c_.slope_threshold_deg >= 90 ? 2.0 : std::sin(Radians(std::max(c_.slope_threshold_deg, 0.0)));
  // The body stands over the feet's centroid, so feet are placed about it: rests off their
  // centroid would otherwise move the character sideways by that offset every step.
  const Vec3 centroid = RestCentroid(c_);
  rest_.clear();
  for (const FootSpec& f : c_.feet) rest_.push_back(f.rest - centroid);
  pair_of_foot_.assign(c_.feet.size(), 0);
  for (size_t p = 0; p < c_.pairs.size(); ++p) {
    Vec3 centre;
    for (int f : c_.pairs[p]) pair_of_foot_[f] = static_cast<int>(p), centre += rest_[f];
    pair_centre_.push_back(centre / static_cast<double>(c_.pairs[p].size()));
  }
  mate_.assign(c_.feet.size(), -1);
  for (size_t f = 0; f < c_.feet.size(); ++f) {
    const std::vector<int>& pair = c_.pairs[pair_of_foot_[f]];
    if (pair.size() == 2) {
      const int other = pair[0] == static_cast<int>(f) ? pair[1] : pair[0];
      if (std::fabs(rest_[f].x - rest_[other].x) > 1e-9) mate_[f] = other;
      continue;
    }
    const Vec3 mirrored{-rest_[f].x, rest_[f].y, rest_[f].z};
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t g = 0; g < c_.feet.size(); ++g) {
      if (rest_[g].x * rest_[f].x >= 0 || Distance(rest_[g], mirrored) >= nearest) continue;
      nearest = Distance(rest_[g], mirrored), mate_[f] = static_cast<int>(g);
    }
  }
  pairs_of_group_.assign(groups, {});
  slot_of_foot_.assign(groups, {});
  move_of_foot_.assign(groups, std::vector<int>(c_.feet.size(), -1));
  for (int g = 0; g < groups; ++g) {
    for (size_t j = 0; j < c_.gait[g].size(); ++j)
      move_of_foot_[g][c_.gait[g][j]] = static_cast<int>(j);
    auto& list = pairs_of_group_[g];
    for (int f : c_.gait[g]) {
      auto it = std::find(list.begin(), list.end(), pair_of_foot_[f]);
      if (it == list.end()) it = list.insert(list.end(), pair_of_foot_[f]);
      slot_of_foot_[g].push_back(static_cast<size_t>(it - list.begin()));
    }
  }
  Status s = Setup(error);
  if (s != Status::kOk) return s;
  // Passes: the characters walk every step in groups of characters_per_pass, so that a group's
  // terrain stays in the caches from one step to the next. In process, passes run in parallel,
  // one per thread (no hand-over between threads within a step).
  const size_t n = agents_.size();
  int per_pass_option = o_.characters_per_pass;
  if (per_pass_option == 0)
    per_pass_option = session_.InProcess() ? kInProcessCharactersPerPass : -1;
  const size_t per_pass = per_pass_option > 0 ? static_cast<size_t>(per_pass_option) : n;
  const size_t passes = (n + per_pass - 1) / per_pass;
  keep_on_failure_ = passes == 1;
  Progress progress(o_.progress, int64_t{steps_} * static_cast<int64_t>(passes));
  if (session_.InProcess() && threads_ > 1 && passes > 1) {
    s = WalkPassesInParallel(passes, per_pass, &progress, error);
  } else {
    for (size_t pass = 0; pass < passes && s == Status::kOk; ++pass)
      s = WalkPass(pass * per_pass, std::min(n, (pass + 1) * per_pass), &progress, error);
  }
  if (s != Status::kOk) return s;
  // A path walk without --steps that used every step it may take without reaching its goal
  // stopped short of what was asked: said as a stop (exit status 2), its keys kept.
  if (o_.steps < 0 && !o_.path.empty()) {
    for (Agent& a : agents_) {
      if (!a.walking || !a.stopped.empty() || a.path.empty()) continue;
      const double left = Remaining(a, a.path.size() - 1);
      std::ostringstream why;
      why.precision(4);
      why << "the path's goal " << Point(a.path.back()) << " is still " << left << " away after "
          << steps_
          << " steps, the most a path walk takes without --steps (give --steps to walk farther)";
      Stop(a, steps_ + 1, why.str());
    }
  }
  // A path walk given its number of steps that took them all short of its goal did as asked
  // (no stop), but says how far the goal still is.
  walk_.notes.clear();
  if (o_.steps >= 0 && !o_.path.empty()) {
    for (Agent& a : agents_) {
      if (!a.walking || !a.stopped.empty() || a.path.empty()) continue;
      size_t next = a.waypoint;  // arrived with the last step?
      while (next < a.path.size() && Reached(a, next)) ++next;
      if (next == a.path.size()) continue;
      std::ostringstream note;
      note.precision(4);
      if (!a.id.empty()) note << a.id << ": ";
      note << "the path's goal " << Point(a.path.back()) << " is still "
           << Remaining(a, a.path.size() - 1) << " away after the " << steps_
           << " steps asked for (without --steps a path walk goes on to its goal, up to "
           << kMaxPathSteps << " steps)";
      walk_.notes.push_back(note.str());
    }
  }
  // The walk's stop message: the earliest stop (the first character's among those of that
  // step), and how many others stopped; Walk::stops has every one.
  std::vector<const Agent*> stopped;
  for (const Agent& a : agents_)
    if (!a.stopped.empty()) stopped.push_back(&a);
  std::stable_sort(stopped.begin(), stopped.end(), [](const Agent* x, const Agent* y) {
    return x->stopped_step < y->stopped_step;
  });
  walk_.stops.clear();
  for (const Agent* a : stopped) walk_.stops.push_back(a->stopped);
  if (!stopped.empty()) walk_.stopped = stopped[0]->stopped;
  if (stopped.size() > 1)
    walk_.stopped += " (and " + std::to_string(stopped.size() - 1) +
                     (stopped.size() == 2 ? " more character" : " more characters") + " stopped)";
  // Characters left out of a crowd leave no tracks.
  if (std::any_of(agents_.begin(), agents_.end(), [](const Agent& a) { return a.left_out; })) {
    const size_t per_agent = c_.feet.size() + 1;
    std::vector<WalkTrack> kept;
    kept.reserve(walk_.tracks.size());
    for (const Agent& a : agents_)
      if (!a.left_out)
        for (size_t t = a.first_track; t < a.first_track + per_agent; ++t)
          kept.push_back(std::move(walk_.tracks[t]));
    walk_.tracks = std::move(kept);
  }
  return Status::kOk;
}

Status Generator::WalkPass(size_t begin, size_t end, Progress* progress, std::string* error) {
  pass_begin_ = begin, pass_end_ = end;
  // The pass's characters' first keys: each thread first writes the keys' memory it fills.
  for (size_t i = begin; i < end; ++i) KeyStart(agents_[i]);
  Status started = KeyBodies(error);
  if (started != Status::kOk) return started;
  int k = 0;
  for (; k < steps_; ++k) {
    bool any = false;
    for (size_t i = begin; i < end && !any; ++i) any = agents_[i].walking;
    if (!any) break;
    const Status s = Step(k, error);
    if (s != Status::kOk) {
      if (k == 0 || !keep_on_failure_) return s;
      StopPassAt(k, *error);
      error->clear();
      break;
    }
    progress->Add(1);
  }
  progress->Add(steps_ - k);  // the steps left when every character stopped or arrived
  return Status::kOk;
}

Status Generator::WalkPassesInParallel(size_t passes, size_t per_pass, Progress* progress,
                                       std::string* error) {
  if (!pool_) pool_ = SharedBatchPool(threads_);
  // The set-up's buffers hold every character's feet; a pass refills them for its own.
  std::vector<Vec3>().swap(points_);
  std::vector<Foothold>().swap(answers_);
  std::vector<Generator> copies(std::min(static_cast<size_t>(threads_), passes), *this);
  for (Generator& g : copies) g.threads_ = 1;
  std::atomic<size_t> next{0};
  std::mutex mutex;
  size_t failed_pass = passes;  // the first pass that failed, under mutex
  Status failure = Status::kOk;
  // One item per copy; each takes passes in turn until none is left (a thread that starts
  // late takes fewer), or a pass failed.
  pool_->Run(copies.size(), 1, [&](size_t b, size_t e) {
    for (size_t c = b; c < e; ++c) {
      for (size_t pass; (pass = next.fetch_add(1)) < passes;) {
        std::string why;
        const size_t first = pass * per_pass;
        const Status s =
            copies[c].WalkPass(first, std::min(agents_.size(), first + per_pass), progress, &why);
        if (s == Status::kOk) continue;
        std::lock_guard<std::mutex> lock(mutex);
        if (pass < failed_pass) failed_pass = pass, failure = s, *error = why;
        next.store(passes);
      }
    }
  });
  return failure;
}

Status Generator::Setup(std::string* error) {
  const size_t feet = c_.feet.size();
  TerrainInfo info;
  Status s = Check(session_.Info(terrain_, &info), "terrain info", error);
  if (s != Status::kOk) return s;
  const GridStats& g = info.stats;
  bounds_min_ = g.bounds_min, bounds_max_ = g.bounds_max;
  gap_ = g.samples > 0
             ? 2 * g.cell_size *
                   std::sqrt(static_cast<double>(g.occupied_cells) / static_cast<double>(g.samples))
             : 0;
  // 1. The start: --start, or the centre of the top of the bounds; either may move to where
  //    the character can stand.
  const Vec3 start =
      o_.has_start ? o_.start : TopCentre(info.stats.bounds_min, info.stats.bounds_max, world_up_);
  Foothold first;
  s = FindStart(start, !o_.has_start || o_.start_may_move, &first, error);
  if (s != Status::kOk) return s;
  // 2. The start frame: up (terrain normal for multipeds, world up for bipeds) and the heading
  //    projected onto the plane perpendicular to it. Crowds stand on a grid in that plane, or,
  //    on ground within 45 degrees of world up, across world up: one bump's normal tilted a
  //    large grid metres above and below the ground, and its places snapped onto the bumps'
  //    tops together (826 of 10,000 insects on gentle bumps started on another's sample).
  const Vec3 up0 = c_.align_to_normal ? first.normal : world_up_;
  const Vec3 fwd0 = StartHeading(up0);
  const Vec3 grid_up = Dot(up0, world_up_) >= std::sqrt(0.5) ? world_up_ : up0;
  const Vec3 grid_fwd = Normalize(ProjectOnPlane(fwd0, grid_up));
  const Vec3 grid_left = Cross(grid_up, grid_fwd);
  const int n = std::max(1, o_.crowd);
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const int rows = (n + cols - 1) / cols;
  const double spacing = o_.crowd_spacing > 0 ? o_.crowd_spacing : 2 * c_.reach;
  std::vector<Vec3> offsets(n);
  points_.resize(n);
  for (int i = 0; i < n; ++i) {
    const double x = (i % cols - (cols - 1) / 2.0) * spacing;
    const double z = (i / cols - (rows - 1) / 2.0) * spacing;
    offsets[i] = n == 1 ? Vec3{} : grid_left * x + grid_fwd * z;
    points_[i] = first.point + offsets[i];
  }
  answers_.resize(n);
  s = Check(session_.Snap(terrain_, points_.data(), n, answers_.data()), "snap start", error);
  if (s != Status::kOk) return s;
  // Where the grid runs off the terrain (or past a narrow one), several places snap onto one
  // edge: a character starting within half the spacing of another stays out (CrowdedStarts).
  const std::vector<int> crowded = CrowdedStarts(points_.data(), answers_.data(), n, 0.5 * spacing);
  std::vector<Vec3> snapped_start(n);
  for (int i = 0; i < n; ++i) snapped_start[i] = answers_[i].point;
  agents_.resize(n);
  walk_.tracks.clear();
  walk_.tracks.reserve(n * (feet + 1));
  // Every track reserves the keys it will have if it walks every step (up to a cap), all in
  // one arena. (Exactly those keys when the steps are given and under the cap; a path walk's
  // steps are only a bound.)
  const size_t groups = c_.gait.size();
  const size_t steps_of_foot = static_cast<size_t>(steps_) / groups + 1;
  constexpr size_t kMaxReserved = 4096;
  const size_t foot_keys = std::min<size_t>(3 * steps_of_foot + 1, kMaxReserved);
  const size_t body_keys = std::min<size_t>(steps_ + 1, kMaxReserved);
  const size_t character_bytes =
      feet * foot_keys * sizeof(WalkKey) + body_keys * (sizeof(WalkKey) + sizeof(Quat));
  const bool exact = o_.steps >= 0 && 3 * steps_of_foot + 1 <= kMaxReserved &&
                     static_cast<size_t>(steps_) + 1 <= kMaxReserved;
  // A heading along the up where the character starts gives no direction on the ground (it
  // used to fall back to another direction silently). Within a few degrees of the up, what is
  // left on the ground is the terrain's tilt, not a direction the user chose: the default +Z
  // heading on a Z-up terrain would walk a multiped downhill.
  if (o_.path.empty() && n > 0) {
    constexpr double kMinDegreesFromUp = 10;
    const double min_sin = std::sin(Radians(kMinDegreesFromUp));
    const Vec3 up = c_.align_to_normal ? answers_[0].normal : world_up_;
    if (Length2(ProjectOnPlane(o_.heading, up)) <= min_sin * min_sin * Length2(o_.heading)) {
      std::ostringstream m;
      m << "the heading " << Point(o_.heading) << " is along the up " << Point(up)
        << " where the character starts (within " << kMinDegreesFromUp
        << " deg of it): it gives no clear direction on the ground; give a heading along the "
           "ground with --heading";
      *error = m.str();
      return Status::kInvalidArgument;
    }
  }
  auto arena = std::make_shared<KeyArena>(n * character_bytes, exact);
  for (int i = 0; i < n; ++i) {
    Agent& a = agents_[i];
    if (n > 1) a.id = "c" + std::to_string(i + 1);
    for (const Vec3& p : o_.path) a.path.push_back(p + offsets[i]);
    Orient(a, answers_[i], up0, fwd0);
    a.first_track = walk_.tracks.size();
    for (size_t f = 0; f <= feet; ++f) {
      const bool body = f == feet;
      WalkTrack t{body ? "body" : c_.feet[f].name,
                  a.id,
                  body ? TrackKind::kBody : TrackKind::kFoot,
                  KeyMemory(arena),
                  std::pmr::vector<WalkKey>(arena.get()),
                  std::pmr::vector<Quat>(arena.get())};
      t.keys.reserve(body ? body_keys : foot_keys);
      if (body) t.rotations.reserve(body_keys);
      walk_.tracks.push_back(std::move(t));
    }
  }
  // 3. Snap the feet at their rest positions around each start.
  points_.resize(n * feet);
  for (int i = 0; i < n; ++i)
    for (size_t f = 0; f < feet; ++f) points_[i * feet + f] = Place(agents_[i], rest_[f]);
  answers_.resize(points_.size());
  s = Check(session_.Snap(terrain_, points_.data(), points_.size(), answers_.data()), "snap feet",
            error);
  if (s == Status::kOk)
    s = SeparateSharedFeet(points_.data(), answers_.data(), points_.size(), feet, error);
  if (s != Status::kOk) return s;
  // 4. The body at the feet's centroid, raised by body_height along its up (multipeds: BodyUp;
  //    the feet's frame from their averaged normal). (Keyed at the start of their pass.)
  for (int i = 0; i < n; ++i) {
    Agent& a = agents_[i];
    const std::string fault = Plant(a, &answers_[i * feet]);
    if (!fault.empty()) {
      Stop(a, 1, fault);
    } else if (crowded[i] >= 0) {
      const Agent& other = agents_[crowded[i]];
      std::ostringstream m;
      m.precision(3);
      m << "step 1 of " << a.id << ": its place on the crowd's grid, "
        << Point(first.point + offsets[i]) << ", snaps to " << Point(snapped_start[i])
        << ", within " << Distance(snapped_start[i], snapped_start[crowded[i]]) << " of "
        << other.id << "'s start (the grid runs off the terrain there): left out of the walk";
      a.walking = false, a.left_out = true;
      a.stopped = m.str(), a.stopped_step = 1;
    }
  }
  // Feet planted exactly where another character's are (places on a terrain's edge whose snaps
  // differ but whose feet snap alike): one of them is left out, as for starts. (Within the gap,
  // characters stopped at step 1 kept neighbours that would have stood apart off.)
  std::vector<Foothold> grounds(static_cast<size_t>(n));
  std::vector<Vec3> places(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    places[i] = first.point + offsets[i];
    grounds[i].point = agents_[i].ground;
    grounds[i].status = agents_[i].left_out ? Status::kNoFoothold : Status::kOk;
  }
  const std::vector<int> stacked = CrowdedStarts(places.data(), grounds.data(), n, 1e-9 * spacing);
  for (int i = 0; i < n; ++i) {
    Agent& a = agents_[i];
    if (stacked[i] < 0 || a.left_out) continue;
    std::ostringstream m;
    m << "step 1 of " << a.id << ": its feet, around " << Point(a.ground) << ", stand where "
      << agents_[stacked[i]].id
      << "'s do (the grid runs off the terrain there): left out of the walk";
    a.walking = false, a.left_out = true;
    a.stopped = m.str(), a.stopped_step = 1;
  }
  // 5 (set-up). How far each waypoint lies from the terrain (one batch of snaps), for Reached.
  const size_t waypoints = o_.path.size();
  if (waypoints > 0) {
    points_.resize(static_cast<size_t>(n) * waypoints);
    for (int i = 0; i < n; ++i)
      std::copy(agents_[i].path.begin(), agents_[i].path.end(), &points_[i * waypoints]);
    // Points beyond the reach of terrain queries are farther from it than anything.
    std::vector<size_t> asked;
    std::vector<Vec3> queries;
    for (size_t j = 0; j < points_.size(); ++j) {
      const Vec3& p = points_[j];
      if (std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) <= terrain::kMaxCoordinate)
        asked.push_back(j), queries.push_back(p);
    }
    answers_.resize(queries.size());
    s = Check(session_.Snap(terrain_, queries.data(), queries.size(), answers_.data()),
              "snap waypoints", error);
    if (s != Status::kOk) return s;
    for (int i = 0; i < n; ++i)
      agents_[i].path_off.assign(waypoints, std::numeric_limits<double>::infinity());
    for (size_t q = 0; q < asked.size(); ++q)
      if (answers_[q].status == Status::kOk)
        agents_[asked[q] / waypoints].path_off[asked[q] % waypoints] =
            Distance(answers_[q].point, queries[q]);
  }
  return Status::kOk;
}

std::vector<int> Generator::CrowdedStarts(const Vec3* places, const Foothold* starts, int n,
                                          double apart) {
  // A hash of cells `apart` wide: only the 27 cells around a start can hold one nearer.
  std::vector<int> crowded(static_cast<size_t>(n), -1);
  if (n < 2 || !(apart > 0)) return crowded;
  struct CellHash {
    size_t operator()(const std::array<int64_t, 3>& c) const {
      return static_cast<size_t>(c[0] * 73856093 ^ c[1] * 19349663 ^ c[2] * 83492791);
    }
  };
  std::unordered_map<std::array<int64_t, 3>, std::vector<int>, CellHash> cells;
  auto cell_of = [apart](const Vec3& p) {
    auto index = [apart](double v) {  // clamped: a tiny spacing must not overflow the cast
      return static_cast<int64_t>(std::clamp(std::floor(v / apart), -9e18, 9e18));
    };
    return std::array<int64_t, 3>{index(p.x), index(p.y), index(p.z)};
  };
  // The characters that snapped nearest their places first (those on the terrain before those
  // pushed onto its edge), in grid order among equals.
  std::vector<int> order(static_cast<size_t>(n));
  std::vector<double> moved(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) order[i] = i, moved[i] = Distance(places[i], starts[i].point);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return moved[a] < moved[b]; });
  for (int i : order) {
    if (starts[i].status != Status::kOk) continue;
    const Vec3& p = starts[i].point;
    const std::array<int64_t, 3> c = cell_of(p);
    for (int64_t dz = -1; dz <= 1 && crowded[i] < 0; ++dz)
      for (int64_t dy = -1; dy <= 1 && crowded[i] < 0; ++dy)
        for (int64_t dx = -1; dx <= 1 && crowded[i] < 0; ++dx) {
          const auto it = cells.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == cells.end()) continue;
          for (int j : it->second)
            if (Distance(starts[j].point, p) < apart) {
              crowded[i] = j;
              break;
            }
        }
    if (crowded[i] < 0) cells[c].push_back(i);  // only characters that walk keep others off
  }
  return crowded;
}

void Generator::KeyStart(const Agent& a) {
  // 4 (end). Every foot and the body keyed planted at the start frame.
  for (size_t f = 0; f < c_.feet.size(); ++f)
    KeyFoot(a, static_cast<int>(f), o_.start_frame, KeyPhase::kEnd, a.foot[f], a.foot_normal[f]);
  body_due_.emplace_back(static_cast<size_t>(&a - agents_.data()), o_.start_frame);
}

double Generator::MaxBodyRaise(const Agent& a) const {
  // |ground + up (h + r) - foot| <= reach for every foot: r below the larger root of a
  // quadratic in r, per foot.
  double most = kBodyRounds * c_.body_height;
  for (const Vec3& foot : a.foot) {
    const Vec3 d = a.ground + a.body_up * c_.body_height - foot;
    const double b = Dot(d, a.body_up), rest = Length2(d) - c_.reach * c_.reach;
    const double disc = b * b - rest;
    most = std::min(most, disc >= 0 ? -b + std::sqrt(disc) : 0.0);
  }
  return std::max(0.0, most);
}

Status Generator::KeyBodies(std::string* error) {
  // 11 (end). The body's clearance, as arcs measure theirs.
  const size_t n = body_due_.size();
  body_raise_.assign(n, 0);
  body_pending_.resize(n);
  for (size_t i = 0; i < n; ++i) body_pending_[i] = i;
  const double need = kBodyClearance * c_.body_height;
  for (int round = 0; round < kBodyRounds && !body_pending_.empty(); ++round) {
    body_points_.resize(body_pending_.size());
    for (size_t j = 0; j < body_pending_.size(); ++j) {
      const size_t i = body_pending_[j];
      const Agent& a = agents_[body_due_[i].first];
      body_points_[j] = a.ground + a.body_up * (c_.body_height + body_raise_[i]);
    }
    answers_.resize(body_points_.size());
    const Status s =
        Check(session_.Snap(terrain_, body_points_.data(), body_points_.size(), answers_.data()),
              "snap bodies", error);
    if (s != Status::kOk) return s;
    body_still_.clear();
    for (size_t j = 0; j < body_pending_.size(); ++j) {
      const size_t i = body_pending_[j];
      const Foothold& h = answers_[j];
      const Agent& a = agents_[body_due_[i].first];
      if (h.status != Status::kOk || Clearance(body_points_[j], h, gap_, a.body_up) >= need)
        continue;
      const double along = Dot(a.body_up, h.normal);
      if (along < 0.25) continue;  // rising would barely leave that face
      const double height = Dot(body_points_[j] - h.point, h.normal);
      // Up to body_height when merely too near; a body inside the terrain (a multiped's between
      // feet on two treads, behind a nose) as far as reach allows.
      const double most = height < 0 ? MaxBodyRaise(a) : std::min(c_.body_height, MaxBodyRaise(a));
      const double raise =
          std::min(body_raise_[i] + std::min((need - height) / along, c_.body_height), most);
      if (raise <= body_raise_[i]) continue;
      // Behind a plane facing along its up (within 45 degrees) that the most it may rise does
      // not take it out of (a roof modelled as one face, facing up, over the body): rising
      // would only go toward it. (A face across its up, the side of a block whose corner the
      // body is in, is left as rising takes the body toward the block's top: the next round
      // judges it from there.)
      if (along >= kAlikeCos && height + (most - body_raise_[i]) * along < 0) continue;
      body_raise_[i] = raise;
      body_still_.push_back(i);
    }
    body_pending_.swap(body_still_);
  }
  // Room for an upright body (kMaxSpineChecks), after the start (where it stands as asked) and
  // when its spine is longer than the gap (shorter, the samples cannot tell).
  spine_first_.assign(n + 1, 0);
  body_points_.clear();
  for (size_t i = 0; i < n; ++i) {
    const Agent& a = agents_[body_due_[i].first];
    const double low = 0.5 * c_.body_height, high = c_.body_height + body_raise_[i];
    const double span = high - low;
    if (!c_.align_to_normal && body_due_[i].second != o_.start_frame && gap_ > 0 && span >= gap_) {
      const size_t count =
          static_cast<size_t>(std::min(std::ceil(span / gap_), kMaxSpineChecks - 1.0)) + 1;
      for (size_t j = 0; j < count; ++j)
        body_points_.push_back(a.ground + a.body_up * (low + span * static_cast<double>(j) /
                                                                 static_cast<double>(count - 1)));
    }
    spine_first_[i + 1] = body_points_.size();
  }
  if (!body_points_.empty()) {
    answers_.resize(body_points_.size());
    const Status s =
        Check(session_.Snap(terrain_, body_points_.data(), body_points_.size(), answers_.data()),
              "snap bodies", error);
    if (s != Status::kOk) return s;
  }
  for (size_t i = 0; i < n; ++i) {
    Agent& a = agents_[body_due_[i].first];
    const double frame = body_due_[i].second;
    // A spine point's nearest sample across the spine: within the gap of its line, above every
    // foot by more than the gap and below the body, its plane crossing the spine (from the gap
    // above the feet's centroid up to the body) within half the gap of it, about one sample
    // spacing (the next nose, two spacings ahead of a biped's spine on steep stairs, crossed it
    // within the gap). Whichever way it faces: a roof modelled as one face is a surface too, and
    // so is a slab below the lowest point checked; a wall beside the spine, or a block's face
    // ahead, does not cross it.
    const double top = c_.body_height + body_raise_[i];
    const Vec3 spine_low = a.ground + a.body_up * gap_;
    const Vec3 spine_top = a.ground + a.body_up * top;
    auto across = [&](const Foothold& h) {
      if (h.status != Status::kOk) return false;
      const Vec3 d = h.point - a.ground;
      if (Dot(d, a.body_up) >= top || Length(ProjectOnPlane(d, a.body_up)) > gap_) return false;
      for (const Vec3& foot : a.foot)
        if (Dot(h.point - foot, a.body_up) <= gap_) return false;
      const double below = Dot(spine_low - h.point, h.normal);
      const double above = Dot(spine_top - h.point, h.normal);
      if ((below > 0) == (above > 0) || below == above) return false;
      const Vec3 crossing = Lerp(spine_low, spine_top, below / (below - above));
      return Distance(crossing, h.point) <= 0.5 * gap_;
    };
    const auto end = answers_.begin() + static_cast<std::ptrdiff_t>(spine_first_[i + 1]);
    const auto crossing =
        std::find_if(answers_.begin() + static_cast<std::ptrdiff_t>(spine_first_[i]), end, across);
    if (crossing == end) {
      KeyBody(a, frame, body_raise_[i]);
      continue;
    }
    std::ostringstream why;
    why << "no room for the body at " << Point(body_points_[spine_first_[i + 1] - 1])
        << ": the terrain at " << Point(crossing->point)
        << " lies between it and its feet (an overhang or a ceiling lower than body_height)";
    UnkeyStep(a, frame - c_.frames_per_step);
    Stop(a, static_cast<int>(std::lround((frame - o_.start_frame) / c_.frames_per_step)),
         why.str());
  }
  body_due_.clear();
  return Status::kOk;
}

void Generator::UnkeyStep(const Agent& a, double f0) {
  // Keys after f0 go; a lift-off at f0 goes too (at the start frame it becomes the plant it
  // replaced again); a touch-down at f0 that a gait of one group lifted from stays.
  for (size_t f = 0; f < c_.feet.size(); ++f) {
    std::pmr::vector<WalkKey>& keys = walk_.tracks[a.first_track + f].keys;
    while (!keys.empty() && keys.back().frame > f0) keys.pop_back();
    if (keys.empty() || keys.back().frame != f0 || keys.back().phase != KeyPhase::kStart) continue;
    if (f0 == o_.start_frame)
      keys.back().phase = KeyPhase::kEnd;
    else
      keys.pop_back();
  }
}

void Generator::StopPassAt(int k, const std::string& why) {
  const double f0 = o_.start_frame + static_cast<double>(k) * c_.frames_per_step;
  for (size_t i = pass_begin_; i < pass_end_; ++i) {
    Agent& a = agents_[i];
    if (!a.walking) continue;
    UnkeyStep(a, f0);
    WalkTrack& body = walk_.tracks[a.first_track + c_.feet.size()];
    while (!body.keys.empty() && body.keys.back().frame > f0) body.keys.pop_back();
    if (body.rotations.size() > body.keys.size()) body.rotations.resize(body.keys.size());
    Stop(a, k + 1, why);
  }
}

Status Generator::SeparateSharedFeet(const Vec3* places, Foothold* feet, size_t total, size_t count,
                                     std::string* error) {
  if (count < 2) return Status::kOk;
  std::vector<size_t> movers;
  for (size_t c = 0; c < total; c += count) {
    for (size_t f = c; f < c + count; ++f) {
      if (feet[f].status != Status::kOk) continue;
      // f moves when another foot of its character shares its sample and is nearer it (or as
      // near, and earlier).
      const double mine = Distance(places[f], feet[f].point);
      for (size_t g = c; g < c + count; ++g) {
        if (g == f || feet[g].status != Status::kOk || feet[g].index != feet[f].index) continue;
        const double theirs = Distance(places[g], feet[g].point);
        if (theirs < mine || (theirs == mine && g < f)) {
          movers.push_back(f);
          break;
        }
      }
    }
  }
  if (movers.empty()) return Status::kOk;
  std::vector<Vec3> far(movers.size());
  for (size_t i = 0; i < movers.size(); ++i) {
    const size_t f = movers[i];
    far[i] = places[f] * 2.0 - feet[f].point;
  }
  std::vector<Foothold> again(movers.size());
  const Status s =
      Check(session_.Snap(terrain_, far.data(), far.size(), again.data()), "snap feet", error);
  if (s != Status::kOk) return s;
  for (size_t i = 0; i < movers.size(); ++i) {
    const size_t f = movers[i], c = f - f % count;
    const Foothold& h = again[i];
    if (h.status != Status::kOk ||
        Distance(places[f], h.point) > Distance(places[f], feet[f].point) + gap_)
      continue;
    bool taken = false;
    for (size_t g = c; g < c + count; ++g) taken |= g != f && feet[g].index == h.index;
    if (!taken) feet[f] = h;
  }
  return Status::kOk;
}

Status Generator::FindStart(const Vec3& start, bool may_move, Foothold* first, std::string* error) {
  Status s = Check(session_.Snap(terrain_, &start, 1, first), "snap start", error);
  if (s != Status::kOk) return s;
  if (first->status != Status::kOk) {
    *error = first->status == Status::kInvalidArgument
                 ? "the start is too far from the terrain to snap (queries reach 1e15 from it)"
                 : "the terrain is empty: no sample to start on";
    return Status::kInvalidArgument;
  }
  if (!may_move) {
    // A start beside the foot of a wall (a box's face nearer than the lattice's next floor
    // sample) takes the ground below it, when that lies within half a step and leans within
    // max_slope_deg of world up: a crowd started 2 cm in front of a box stood on a grid up its
    // face. A start up a wall or on a ceiling (even a thin one: not the ground above) stays.
    if (Dot(first->normal, world_up_) >= cos_max_slope_) return Status::kOk;
    const double beside = kFootholdTolerance * c_.step_length;
    const Vec3 below = start - world_up_ * beside;
    Foothold ground;
    s = Check(session_.Snap(terrain_, &below, 1, &ground), "snap start", error);
    if (s == Status::kOk && ground.status == Status::kOk &&
        Dot(ground.normal, world_up_) >= cos_max_slope_ &&
        Dot(start - ground.point, world_up_) >= 0 && Distance(ground.point, start) <= beside)
      *first = ground;
    return s;
  }
  // Candidates on a grid of half a step across world up through the start's sample, nearest
  // it first (the start itself first), each snapped; then the feet of one character standing
  // on each. (A candidate snaps to the nearest sample: beside a tall feature it may snap to
  // the feature's side rather than the ground below, and the search goes on farther out.)
  const Vec3 centre = first->point;
  const double cell = 0.5 * c_.step_length;
  const int k = 2 * kStartSearchSteps;
  std::vector<std::pair<int, int>> grid;
  for (int j = -k; j <= k; ++j)
    for (int i = -k; i <= k; ++i)
      if (i * i + j * j <= k * k) grid.emplace_back(i, j);
  std::stable_sort(grid.begin(), grid.end(), [](const auto& a, const auto& b) {
    return a.first * a.first + a.second * a.second < b.first * b.first + b.second * b.second;
  });
  const Vec3 u = AnyPerpendicular(world_up_), v = Cross(world_up_, u);
  const size_t feet = c_.feet.size();
  const double beside = kFootholdTolerance * c_.step_length;
  std::vector<Vec3> points;
  std::vector<Foothold> grounds, snapped;
  std::vector<Agent> stand;
  bool level_feet = true;  // the first search: every foot on ground within max_slope_deg
  // Candidates [b, e): sets *found to the first where the character can stand.
  auto search = [&](size_t b, size_t e, bool* found) -> Status {
    points.resize(e - b);
    for (size_t m = b; m < e; ++m)
      points[m - b] = centre + u * (grid[m].first * cell) + v * (grid[m].second * cell);
    grounds.resize(points.size());
    Status st = Check(session_.Snap(terrain_, points.data(), points.size(), grounds.data()),
                      "snap start", error);
    if (st != Status::kOk) return st;
    stand.assign(grounds.size(), Agent{});
    points.assign(grounds.size() * feet, Vec3{});
    for (size_t m = 0; m < grounds.size(); ++m) {
      if (grounds[m].status != Status::kOk) continue;
      const Vec3 up0 = c_.align_to_normal ? grounds[m].normal : world_up_;
      stand[m].path = o_.path;
      Orient(stand[m], grounds[m], up0, StartHeading(up0));
      for (size_t f = 0; f < feet; ++f) points[m * feet + f] = Place(stand[m], rest_[f]);
    }
    snapped.resize(points.size());
    st = Check(session_.Snap(terrain_, points.data(), points.size(), snapped.data()), "snap feet",
               error);
    if (st != Status::kOk) return st;
    for (size_t m = 0; m < grounds.size() && !*found; ++m) {
      if (grounds[m].status != Status::kOk) continue;
      Agent& a = stand[m];
      bool near = true;  // every foot near its rest position, along up and across it
      for (size_t f = 0; f < feet && near; ++f) {
        const Foothold& h = snapped[m * feet + f];
        const Vec3 d = h.point - points[m * feet + f];
        // ... and, in the first search, on ground within max_slope_deg of the up it was placed
        // with (Plant judges the feet's averaged normal: two paws on a stair's riser and two on
        // its tread averaged 45 degrees, and the default start stood them there).
        near = h.status == Status::kOk && std::fabs(Dot(d, a.up)) <= c_.max_rise &&
               Length(ProjectOnPlane(d, a.up)) <= beside &&
               (!level_feet || Dot(h.normal, a.up) >= cos_max_slope_);
      }
      if (near && Plant(a, &snapped[m * feet]).empty()) *found = true, *first = grounds[m];
    }
    return Status::kOk;
  };
  // The start alone first: usually the character stands there, and nothing more is asked. A
  // place with every foot on level enough ground first; else one where Plant accepts the feet
  // (a diagonal across a flight of stairs has no place of the first kind within reach).
  bool found = false;
  for (bool level : {true, false}) {
    level_feet = level;
    s = search(0, 1, &found);
    if (s == Status::kOk && !found) s = search(1, grid.size(), &found);
    if (s != Status::kOk || found) break;
  }
  return s;  // found nowhere: the start's own sample, where Setup says why it cannot stand
}

void Generator::Orient(Agent& a, const Foothold& ground, const Vec3& up0, const Vec3& fwd0) const {
  a.ground = ground.point;
  a.up = c_.align_to_normal ? ground.normal : world_up_;
  a.forward = TangentForward(o_.heading, fwd0, up0, a.up);
  // Facing the first waypoint beyond its radius along the ground: one at the start (a path
  // drawn from where the character stands) counts as reached on the first step, so it gives no
  // direction. (Before the waypoints' distances from the terrain are known: taken as off it.)
  for (size_t i = 0; i < a.path.size(); ++i) {
    const Vec3 to = ProjectOnPlane(ToPathPoint(a, a.path[i], false), a.up);
    if (Length(to) > Radius(a, i)) {
      a.forward = Normalize(to);
      return;
    }
  }
  // Every waypoint within its radius: toward the first that is off the start at all.
  for (const Vec3& p : a.path) {
    const Vec3 to = ProjectOnPlane(ToPathPoint(a, p, false), a.up);
    if (Length2(to) > 1e-18) {
      a.forward = Normalize(to);
      return;
    }
  }
}

std::string Generator::Plant(Agent& a, const Foothold* feet) const {
  const size_t n = c_.feet.size();
  a.foot.resize(n), a.foot_normal.resize(n);
  Vec3 centroid;
  for (size_t f = 0; f < n; ++f) {
    a.foot[f] = feet[f].point, a.foot_normal[f] = feet[f].normal;
    centroid += a.foot[f];
  }
  const Vec3 old_up = a.up;
  a.up = AveragedUp(a.up, a.foot_normal);
  a.body_up = BodyUp(a.up, a.foot);
  a.forward = TangentForward(a.forward, a.forward, old_up, a.up);
  a.ground = centroid / static_cast<double>(n);
  for (size_t f = 0; f < n; ++f) {
    const double slope = Degrees(AngleBetween(a.foot_normal[f], a.up));
    if (slope > c_.max_slope_deg) {
      std::ostringstream m;
      m.precision(3);
      m << "foot " << c_.feet[f].name << " cannot stand at " << Point(a.foot[f])
        << ": ground leans " << Beyond(slope, c_.max_slope_deg) << " deg, more than max_slope_deg "
        << NumberText(c_.max_slope_deg) << FacingDownHint(slope);
      // An upright character starting on ground across its up: a terrain whose up is another
      // axis (a height map read with --up-axis z) with the default world up.
      if (!c_.align_to_normal && slope > 60 && slope < 120)
        m << "; if the terrain's up is not " << Point(world_up_)
          << ", give the world up with --up (Z up: --up 0,0,1)";
      return m.str();
    }
  }
  return "";
}

Status Generator::QueryFootholds(std::string* error) {
  const size_t feet = c_.feet.size();
  std::vector<Move>& moves = moves_;
  const size_t per_agent = walking_.empty() ? 0 : moves.size() / walking_.size();
  const size_t locators = pairs_of_group_[group_].size();
  const std::vector<size_t>& slot = slot_of_foot_[group_];
  // The moves of this pass's characters still without a foothold (all of them in the first pass).
  pending_.clear();
  for (size_t w : walkers_)
    for (size_t m = w * per_agent; m < (w + 1) * per_agent; ++m)
      if (!moves[m].done && !moves[m].failed) pending_.push_back(m);
  for (int round = 0; !pending_.empty(); ++round) {
    // 7. Target locators: the foot's rest offset from its pair's centre, in the frame of the
    //    central locator (aligned to the terrain normal under it). The step vector runs from
    //    the foot to its target; slope awareness and the reach limit shorten it.
    Parallel(pending_.size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        Move& mv = moves[pending_[i]];
        const Agent& a = agents_[mv.agent];
        if (round == 0) {
          // 6 (end). A locator that snapped farther than `lead` from where it was placed hangs
          // over a gap or a cliff: it keeps its place (the body's frame), so the foothold query
          // looks over the void. Round 0 holds every move, and answers_ the locator snaps.
          const size_t m = pending_[i];
          const size_t l = (m / per_agent) * locators + slot[m % per_agent];
          const Foothold& h = answers_[l];
          const Vec3& placed = points_[l];
          if (Distance(h.point, placed) <= lead_) {
            locator_[m] = h.point, locator_normal_[m] = h.normal;
            // On a face past max_slope_deg it keeps its place across the heading (a wall beside
            // it drew the feet sideways into the wall), and on a face across the heading (a wall
            // beside the body, rather than a riser ahead) its height too, as over a gap (aimed at
            // the wall's height, steps beside it were a third of step_length).
            const Vec3 left = Left(a);
            if (Dot(h.normal, a.up) < cos_max_slope_) {
              if (std::fabs(Dot(h.normal, left)) > std::fabs(Dot(h.normal, a.forward)))
                locator_[m] = placed - a.up * (0.5 * lead_), locator_normal_[m] = a.up;
              else
                locator_[m] -= left * Dot(h.point - placed, left);
            } else if (!c_.align_to_normal) {
              // Snapped from lead/2 above along the world up, onto ground leaning across the
              // heading, it slid toward the high side by up to lead/4 (a biped crossing a
              // 25-degree slope climbed 2 m in 10): it slides back along the ground to where
              // it was placed across the heading. (Not past what the lean explains: an edge
              // beside it. Multipeds' up is the ground's normal: they slide along it.)
              const Vec3 across = ProjectOnPlane(left, h.normal);
              const double lean = std::fabs(Dot(h.normal, left));
              const double off = Dot(h.point - placed, left);
              const double keep = Dot(across, left);  // 1 - lean^2
              if (keep > 0.25 && std::fabs(off) <= 0.5 * lead_ * lean + 0.5 * gap_)
                locator_[m] -= across * (off / keep);
            }
          } else {
            locator_[m] = placed - a.up * (0.5 * lead_), locator_normal_[m] = a.up;
          }
        }
        const int p = pair_of_foot_[mv.foot];
        Vec3 n = locator_normal_[pending_[i]];
        if (Dot(n, a.up) < cos_max_slope_) n = a.up;  // leans past max_slope_deg: an edge
        const Vec3 f = TangentForward(a.forward, a.forward, a.up, n);
        const Vec3 l = Cross(n, f);
        const Vec3 d = rest_[mv.foot] - pair_centre_[p];
        const Vec3 target = locator_[pending_[i]] + l * d.x + n * d.y + f * d.z;
        double max_len = c_.step_length;  // shorter where the heading climbs or falls steeply
        if (std::fabs(Dot(f, a.up)) > sin_slope_threshold_) max_len *= c_.slope_step_scale;
        Vec3 v = target - a.foot[mv.foot];
        const double len = Length(v);
        if (len > max_len) v = v * (max_len / len);
        // Longer and aimed-down retries reach a full step along the target's direction: a
        // target locator caught on a stair's nose lies just ahead of a foot standing there.
        if ((mv.attempt.scale > 1 || mv.attempt.drop > 0) && len > kInPlace * c_.step_length)
          v = v * (max_len / Length(v));
        v = v * mv.attempt.scale;  // retries step shorter or longer
        // A foothold lined up with its pair's other foot is asked again with the step aimed
        // outward by half the samples' spacing, toward the sample on the foot's own side.
        if (mv.outward) {
          const double side = rest_[mv.foot].x > rest_[mate_[mv.foot]].x ? 1.0 : -1.0;
          v += Left(a) * (side * 0.25 * gap_);
        }
        if (Length(v) < kInPlace * c_.step_length) {
          if (mv.attempt.drop > 0) {
            Fail(mv);  // nothing ahead to aim down at
          } else {
            mv.done = true, mv.end = a.foot[mv.foot], mv.end_normal = a.foot_normal[mv.foot];
          }
          continue;
        }
        // No target beyond reach of the body where the step will put it (the feet's centroid
        // moves by this foot's displacement over the number of feet).
        for (int shrink = 0; shrink < 8; ++shrink) {
          const Vec3 ground = a.ground + v / static_cast<double>(feet);
          const Vec3 body = ground + a.body_up * c_.body_height;
          if (Distance(a.foot[mv.foot] + v, body) <= c_.reach) break;
          v = v * 0.75;
        }
        v -= a.up * (mv.attempt.drop * c_.max_rise);  // the last retries aim down
        mv.ideal = a.foot[mv.foot] + v, mv.step = v;
      }
    });
    queries_.clear();
    for (size_t m : pending_) {
      if (moves[m].done || moves[m].failed) continue;  // a step in place; nothing to aim at
      moves[m].query = queries_.size();
      queries_.push_back({agents_[moves[m].agent].foot[moves[m].foot], moves[m].step});
    }
    // 8. Query the next foothold of every pending foot of every character: one batch. The
    //    answer carries the end normal; the start normal is the planted foot's.
    if (queries_.empty()) break;
    next_answers_.resize(queries_.size());
    const Status s = Check(session_.Next(terrain_, queries_.data(), queries_.size(),
                                         kFootholdTolerance * c_.step_length, next_answers_.data()),
                           "next foothold", error);
    if (s != Status::kOk) return s;
    // Per character (its moves are contiguous): accept or refuse each answered foot, then the
    // reach limit on the body where the accepted footholds put it; feet beyond it retry.
    Parallel(walkers_.size(), [&](size_t wb, size_t we) {
      for (size_t i = wb; i < we; ++i) {
        const size_t m = walkers_[i] * per_agent, e = m + per_agent;
        bool all_done = true;
        for (size_t j = m; j < e; ++j) {
          if (moves[j].query != kNoQuery) {
            Judge(moves[j], next_answers_[moves[j].query]), moves[j].query = kNoQuery;
            if (!moves[j].done && moves[j].attempts >= kMaxAttempts) KeepPlace(moves[j]);
          }
          all_done &= moves[j].done;
        }
        if (all_done) CheckReach(m, e);
      }
    });
    pending_.clear();
    for (size_t w : walkers_) {
      for (size_t m = w * per_agent; m < (w + 1) * per_agent; ++m) {
        Move& mv = moves[m];
        if (mv.done || mv.failed) continue;
        if (mv.attempts >= kMaxAttempts)
          Fail(mv);
        else
          mv.attempt = kAttempts[mv.attempts], pending_.push_back(m);
      }
    }
  }
  return Status::kOk;
}

void Generator::Judge(Move& mv, const Foothold& h) const {
  const Agent& a = agents_[mv.agent];
  const Vec3& foot = a.foot[mv.foot];
  ++mv.attempts;
  // A foothold must make half the intended progress along the ground it lands on (the step
  // vector projected onto its tangent plane), so no foot creeps sideways along a cliff's edge.
  // Steps mostly along the foothold's normal (onto a wall ahead) are exempt.
  // A step aimed down is judged on the progress it was aimed to make.
  const Vec3 intended = mv.step + a.up * (mv.attempt.drop * c_.max_rise);
  double progress = 1;
  if (h.status == Status::kOk) {
    const Vec3 along = ProjectOnPlane(intended, h.normal);
    if (Length2(along) >= 0.25 * Length2(intended))
      progress = Dot(h.point - foot, along) / Length2(along);
  }
  const bool found = h.status == Status::kOk && progress >= 0.5;
  const double rise = found ? Dot(h.point - foot, a.up) : 0;
  if (found && std::fabs(rise) <= c_.max_rise && Dot(h.normal, a.up) >= cos_max_slope_) {
    if (KeepsSide(mv, h.point, h.normal)) mv.done = true;
    return;
  }
  if (mv.lined_up) {  // the outward retry was refused: the lined-up foothold it tried to better
    mv.done = true, mv.end = mv.lined_up_point, mv.end_normal = mv.lined_up_normal;
    return;
  }
  if (!KeepsReason(mv, !found)) return;  // mv already has a better reason
  std::ostringstream why;                // refused: say why (only built on this rare path)
  why.precision(3);
  if (!found) {
    // Past the terrain's bounds by more than the radius, no sample can be a foothold.
    const double radius = kFootholdTolerance * c_.step_length;
    const bool beyond = BoxDistance(mv.ideal, bounds_min_, bounds_max_) > radius;
    why << "no foothold within " << radius << " of " << Point(mv.ideal)
        << (beyond ? " (the terrain ends, or rises as a wall at its bounds, before it)"
                   : " (a gap or a cliff)");
    // Samples spread wider than half that radius leave gaps everywhere: say so, unless the
    // terrain simply ends there or resampling would not bring them closer.
    const double spacing = 0.5 * gap_;
    if (!beyond && spacing > 0.5 * kFootholdTolerance * c_.step_length &&
        kSeparationPerStep * c_.step_length < 0.8 * spacing) {
      why << "; the terrain's samples lie about " << spacing
          << " apart, too far for this character: resample it at a separation of "
          << kSeparationPerStep * c_.step_length;
    }
  } else if (std::fabs(rise) > c_.max_rise) {
    why << "the foothold at " << Point(h.point) << (rise > 0 ? " rises " : " drops ")
        << Beyond(std::fabs(rise), c_.max_rise) << ", more than max_rise "
        << NumberText(c_.max_rise) << " (a cliff)";
  } else {
    const double slope = Degrees(AngleBetween(h.normal, a.up));
    why << "the foothold at " << Point(h.point) << " leans " << Beyond(slope, c_.max_slope_deg)
        << " deg, more than max_slope_deg " << NumberText(c_.max_slope_deg) << " (too steep)"
        << FacingDownHint(slope);
  }
  mv.reason = why.str(), mv.reason_is_gap = !found;
}

double Generator::GapToMate(const Move& mv, const Vec3& p) const {
  const int mate = mate_[mv.foot];
  if (mate < 0) return 1;
  const Agent& a = agents_[mv.agent];
  return Dot(p - a.foot[mate], Left(a)) / (rest_[mv.foot].x - rest_[mate].x);
}

bool Generator::KeepsSide(Move& mv, const Vec3& p, const Vec3& normal) const {
  const double gap = GapToMate(mv, p);
  if (mv.lined_up) {  // the outward retry: the better of the two
    if (std::fabs(gap - 1) >= std::fabs(mv.lined_up_gap - 1))
      mv.end = mv.lined_up_point, mv.end_normal = mv.lined_up_normal;
    else
      mv.end = p, mv.end_normal = normal;
    return true;
  }
  mv.end = p, mv.end_normal = normal;
  // Lined up: under half the rest gap, with samples at least a quarter of it apart (nearer
  // samples would have given a foothold on the foot's own side).
  if (gap >= kMinPairGap || mv.outward) return true;
  const double rest_gap = std::fabs(rest_[mv.foot].x - rest_[mate_[mv.foot]].x);
  if (0.5 * gap_ < 0.25 * rest_gap) return true;
  mv.outward = true, mv.lined_up = true, mv.lined_up_gap = gap;
  mv.lined_up_point = p, mv.lined_up_normal = normal;
  --mv.attempts;  // the same attempt again, aimed outward
  return false;
}

void Generator::KeepPlace(Move& mv) const {
  const Agent& a = agents_[mv.agent];
  const Vec3 intended = mv.step + a.up * (mv.attempt.drop * c_.max_rise);
  if (Dot(intended, a.forward) >= 0 && a.stride >= 1) return;
  mv.done = true, mv.end = a.foot[mv.foot], mv.end_normal = a.foot_normal[mv.foot];
}

void Generator::Fail(Move& mv) {
  mv.failed = true;
  if (mv.attempts > 1)
    mv.reason += " (" + std::to_string(mv.attempts - 1) +
                 " more tries, shorter, longer or aimed down, refused too)";
}

void Generator::CheckReach(size_t m, size_t e) {
  std::vector<Move>& moves = moves_;
  const size_t feet = c_.feet.size();
  const Agent& a = agents_[moves[m].agent];
  const std::vector<int>& slot = move_of_foot_[group_];  // foot -> its move's offset, or -1
  // The feet and normals after this step, each moving foot at its foothold (per-thread
  // scratch: characters are judged in parallel).
  thread_local std::vector<Vec3> after, after_normals;
  after.resize(feet), after_normals.resize(feet);
  Vec3 centroid;
  for (size_t f = 0; f < feet; ++f) {
    const bool moving = slot[f] >= 0;
    after[f] = moving ? moves[m + slot[f]].end : a.foot[f];
    after_normals[f] = moving ? moves[m + slot[f]].end_normal : a.foot_normal[f];
    centroid += after[f];
  }
  const Vec3 up = BodyUp(FeetUp(a.up, after, after_normals), after);
  const Vec3 body = centroid / static_cast<double>(feet) + up * c_.body_height;
  for (size_t i = m; i < e; ++i) {
    const double dist = Distance(moves[i].end, body);
    if (dist > c_.reach) {
      std::ostringstream why;
      why.precision(3);
      why << "the foothold at " << Point(moves[i].end) << " is " << Beyond(dist, c_.reach)
          << " from the body, beyond reach " << NumberText(c_.reach);
      moves[i].done = false;
      if (KeepsReason(moves[i], false)) moves[i].reason = why.str(), moves[i].reason_is_gap = false;
    }
  }
  // A planted foot the body would leave beyond reach: every moving foot steps shorter.
  for (size_t f = 0; f < feet; ++f) {
    const double dist = Distance(a.foot[f], body);
    if (slot[f] >= 0 || dist <= c_.reach) continue;
    std::ostringstream why;
    why.precision(3);
    why << "the step would leave foot " << c_.feet[f].name << " " << Beyond(dist, c_.reach)
        << " from the body, beyond reach " << NumberText(c_.reach);
    for (size_t i = m; i < e; ++i) {
      if (!moves[i].done) continue;
      moves[i].done = false, moves[i].held_by_planted = true;
      if (KeepsReason(moves[i], false)) moves[i].reason = why.str(), moves[i].reason_is_gap = false;
    }
    break;
  }
}

Status Generator::ClearArcs(int k, std::string* error) {
  // 9. Swing arcs: the mid key is the midpoint of start and end raised along the averaged
  //    normal by step_height. Points along the start-mid-end arc are snapped to the terrain; an
  //    arc passing below it (or too close) raises the mid key, round after round. A character
  //    is finished (10-11) in the round where none of its arcs was raised.
  std::vector<Move>& moves = moves_;
  const size_t per_agent = walking_.empty() ? 0 : moves.size() / walking_.size();
  // Round 0: this pass's characters, with the moves whose foothold was accepted.
  pending_.clear();
  arc_agents_.clear();
  retry_.assign(walking_.size(), 0);
  for (size_t w : walkers_) {
    const size_t begin = pending_.size();
    for (size_t m = w * per_agent; m < (w + 1) * per_agent; ++m)
      if (moves[m].done) pending_.push_back(m);
    arc_agents_.push_back({w, begin, pending_.size()});
  }
  for (int round = 0; !arc_agents_.empty(); ++round) {
    arc_first_.resize(pending_.size() + 1);
    Parallel(pending_.size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        Move& mv = moves[pending_[i]];
        const Agent& a = agents_[mv.agent];
        const Vec3& start = a.foot[mv.foot];
        if (round == 0) {
          mv.mid_normal = NormalizeOr(a.foot_normal[mv.foot] + mv.end_normal, a.up);
          mv.mid = (start + mv.end) * 0.5 + mv.mid_normal * c_.step_height;
        }
        const double half = std::max(Distance(start, mv.mid), Distance(mv.mid, mv.end));
        arc_first_[i + 1] = ArcChecks(2 * half, gap_);
      }
    });
    arc_first_[0] = 0;
    for (size_t i = 0; i < pending_.size(); ++i) arc_first_[i + 1] += arc_first_[i];
    arc_points_.resize(arc_first_[pending_.size()]);
    Parallel(pending_.size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const Move& mv = moves[pending_[i]];
        const Vec3& start = agents_[mv.agent].foot[mv.foot];
        const size_t first = arc_first_[i], checks = arc_first_[i + 1] - first;
        for (size_t j = 0; j < checks; ++j) {
          const double s = ArcS(j, checks);
          arc_points_[first + j] =
              s <= 0.5 ? Lerp(start, mv.mid, 2 * s) : Lerp(mv.mid, mv.end, 2 * s - 1);
        }
      }
    });
    if (!pending_.empty()) {
      arc_answers_.resize(arc_points_.size());
      const Status s = Check(
          session_.Snap(terrain_, arc_points_.data(), arc_points_.size(), arc_answers_.data()),
          "snap swing arc", error);
      if (s != Status::kOk) return s;
    }
    verdict_.assign(pending_.size(), 0);  // 1: raise and check again
    raised_.assign(arc_agents_.size(), 0);
    Parallel(arc_agents_.size(), [&](size_t b, size_t e) {
      for (size_t g = b; g < e; ++g) {
        const ArcAgent& aa = arc_agents_[g];
        for (size_t i = aa.begin; i < aa.end; ++i) {
          Move& mv = moves[pending_[i]];
          const Agent& a = agents_[mv.agent];
          bool low[2] = {false, false};   // a check point too low in the first, second half
          bool wall[2] = {false, false};  // ... beside a face unlike that half's foothold
          const size_t first = arc_first_[i], checks = arc_first_[i + 1] - first;
          for (size_t j = 0; j < checks; ++j) {
            const Foothold& h = arc_answers_[first + j];
            const double s = ArcS(j, checks);
            if (h.status != Status::kOk) continue;
            const int half = s > 0.5;
            const double nominal = c_.step_height * (1 - std::fabs(2 * s - 1));
            const double need =
                ClearanceNeeded(kClearanceFraction * nominal, h, half ? mv.end : a.foot[mv.foot],
                                half ? mv.end_normal : a.foot_normal[mv.foot], c_.step_height);
            if (Clearance(arc_points_[first + j], h, gap_, a.up) < need) {
              low[half] = true;
              wall[half] |= need < kClearanceFraction * nominal;
            }
          }
          if (!low[0] && !low[1]) continue;
          if (round + 1 >= kMaxRaises) {
            // The foot asks for another foothold (its next try), or gives up after the last.
            if (KeepsReason(mv, false)) {
              std::ostringstream why;
              why.precision(3);
              why << "the swing arc to " << Point(mv.end)
                  << " cannot clear the terrain (mid key raised " << kMaxRaises * kRaise
                  << " step heights)";
              mv.reason = why.str(), mv.reason_is_gap = false;
            }
            mv.done = false;
            if (mv.attempts >= kMaxAttempts) {
              Fail(mv);
            } else {
              mv.attempt = kAttempts[mv.attempts];
              retry_[aa.walking] = 1;
            }
            continue;
          }
          mv.mid += mv.mid_normal * (kRaise * c_.step_height);
          // Between footholds that face alike, the mid key also slides toward the start when
          // the first half is low (a riser just ahead of the lifting foot: it lifts before it
          // travels), else toward the end (a nose just behind the landing foot: it travels
          // before it lands); all the way when that foot stands against the face (a toe at a
          // riser lifts straight up). (Over an edge between faces, raising alone clears it.)
          if (Dot(a.foot_normal[mv.foot], mv.end_normal) >= kAlikeCos) {
            const int half = low[0] ? 0 : 1;
            const Vec3& end = half == 0 ? a.foot[mv.foot] : mv.end;
            mv.mid += ProjectOnPlane(end - mv.mid, mv.mid_normal) * (wall[half] ? 1.0 : kSlide);
          }
          verdict_[i] = 1, raised_[g] = 1;
        }
        if (!raised_[g] && !retry_[aa.walking]) Finish(aa.walking, k);
      }
    });
    // The next round: the characters with a raised arc, and only those arcs.
    still_.clear();
    next_agents_.clear();
    for (size_t g = 0; g < arc_agents_.size(); ++g) {
      if (!raised_[g]) continue;
      const size_t begin = still_.size();
      for (size_t i = arc_agents_[g].begin; i < arc_agents_[g].end; ++i)
        if (verdict_[i]) still_.push_back(pending_[i]);
      next_agents_.push_back({arc_agents_[g].walking, begin, still_.size()});
    }
    pending_.swap(still_);
    arc_agents_.swap(next_agents_);
  }
  // The next pass: the characters with a foot to place again.
  walkers_.clear();
  for (size_t w = 0; w < retry_.size(); ++w)
    if (retry_[w]) walkers_.push_back(w);
  return Status::kOk;
}

// 10. Key each foot (start, mid, end) and plant it; 11. move the body to the feet's centroid,
//     raised along its up (multipeds: BodyUp; the feet's frame: FeetUp), heading carried along,
//     and key it at touch-down. A character with a refused foot stops before this step's keys.
void Generator::Finish(size_t w, int k) {
  const size_t per_agent = moves_.size() / walking_.size();
  const double f0 = o_.start_frame + static_cast<double>(k) * c_.frames_per_step;
  const double f_mid = f0 + 0.5 * c_.frames_per_step;
  const double f1 = f0 + c_.frames_per_step;
  const size_t m = w * per_agent, e = m + per_agent;
  Agent& a = agents_[walking_[w]];
  const bool near_window_from = Distance(a.ground, a.window_from) < 0.5 * c_.step_length;
  a.window_left |= !near_window_from;
  if (a.window_step < 0 || k - a.window_step >= window_steps_) {
    if (a.window_step >= 0 && near_window_from && !a.window_left) {
      std::ostringstream why;
      why.precision(4);
      why << "no way forward from " << Point(a.ground) << ": the body has stayed within half a "
          << "step of it for " << window_steps_ << " steps (a dead end)";
      Stop(a, k + 1, why.str());
      return;
    }
    a.window_from = a.ground, a.window_step = k, a.window_left = false;
  }
  const Move* failed = nullptr;
  for (size_t i = m; i < e && !failed; ++i)
    if (!moves_[i].done) failed = &moves_[i];
  bool in_place = true;
  for (size_t i = m; i < e; ++i)
    in_place &= moves_[i].done && moves_[i].end == a.foot[moves_[i].foot];
  // Every foot of the group steps in place: it waits, as a held group does, for the other
  // groups to move the body on (a hind foot at the terrain's back edge, whose target lies behind
  // it until the front feet step); a whole cycle of groups in place is a dead end.
  // A character turning on the spot or at a short stride toward a near waypoint may step in
  // place for as long as its turn takes (the dead-end window allows half a turn).
  if (in_place && !failed && a.stride < 1) {
    ++a.still;
    body_frame_[w] = f1;
    return;
  }
  if (in_place && !failed && a.waits + 1 < static_cast<int>(c_.gait.size())) {
    ++a.waits, ++a.still;
    body_frame_[w] = f1;
    return;
  }
  if (in_place && !failed) {
    Stop(a, k + 1,
         "no way forward from " + Point(a.ground) +
             ": every target is where its foot already stands (a cliff, a gap or a dead end)");
    return;
  }
  // Held back only by a planted foot the body would leave beyond reach: the group waits, its
  // feet planted and the body still (keyed in place at touch-down), and the other groups, that
  // foot's among them, step on; after a whole cycle of such waits in a row the walk stops.
  bool held = failed != nullptr;
  for (size_t i = m; i < e && held; ++i) held = moves_[i].done || moves_[i].held_by_planted;
  if (held && a.waits + 1 < static_cast<int>(c_.gait.size())) {
    ++a.waits, ++a.still;
    body_frame_[w] = f1;
    return;
  }
  if (failed) {
    Stop(a, k + 1,
         "foot " + c_.feet[failed->foot].name + " at " + Point(a.foot[failed->foot]) + ": " +
             failed->reason);
    return;
  }
  a.waits = 0, a.still = 0;
  for (size_t i = m; i < e; ++i) {
    const Move& mv = moves_[i];
    KeyFoot(a, mv.foot, f0, KeyPhase::kStart, a.foot[mv.foot], a.foot_normal[mv.foot]);
    KeyFoot(a, mv.foot, f_mid, KeyPhase::kMid, mv.mid, mv.mid_normal);
    KeyFoot(a, mv.foot, f1, KeyPhase::kEnd, mv.end, mv.end_normal);
    a.foot[mv.foot] = mv.end, a.foot_normal[mv.foot] = mv.end_normal;
  }
  Vec3 centroid;
  for (const Vec3& p : a.foot) centroid += p;
  a.ground = centroid / static_cast<double>(a.foot.size());
  const Vec3 old_up = a.up;
  a.up = FeetUp(a.up, a.foot, a.foot_normal);
  a.body_up = BodyUp(a.up, a.foot);
  a.forward = TangentForward(a.forward, a.forward, old_up, a.up);
  body_frame_[w] = f1;  // keyed by KeyBodies at the end of the step
}

Status Generator::Step(int k, std::string* error) {
  group_ = k % static_cast<int>(c_.gait.size());
  // 5. Heading: turn toward the current waypoint of the path (at most max_turn_deg).
  walking_.clear();
  for (size_t i = pass_begin_; i < pass_end_; ++i) {
    if (!agents_[i].walking) continue;
    Steer(agents_[i], group_);
    if (agents_[i].walking && !Nearing(agents_[i], k)) {
      Agent& a = agents_[i];
      const Vec3& p = a.path[a.waypoint];
      std::ostringstream why;
      why.precision(4);
      why << "no way to " << (a.waypoint + 1 == a.path.size() ? "the path's goal " : "waypoint ")
          << (a.waypoint + 1 == a.path.size() ? "" : std::to_string(a.waypoint + 1) + " ")
          << Point(p) << ": the body has come no nearer to it than " << a.nearest << " for "
          << window_steps_ << " steps";
      Stop(a, k + 1, why.str());
    }
    if (agents_[i].walking) walking_.push_back(i);
  }
  // 6. Central locators: one per foot pair stepping now, `lead` ahead of the pair's rest centre
  //    in the body frame and lead/2 above it (so that at a wall ahead the locator snaps onto the
  //    wall, not into the corner), snapped to the terrain (one batch for every character).
  if (walking_.empty()) return Status::kOk;
  const std::vector<int>& stepping = c_.gait[group_];
  const std::vector<int>& pairs = pairs_of_group_[group_];
  const size_t per_agent = stepping.size(), locators = pairs.size();
  if (per_agent == 0) return Status::kOk;
  moves_.resize(walking_.size() * per_agent);
  points_.resize(walking_.size() * locators);
  locator_.resize(moves_.size()), locator_normal_.resize(moves_.size());
  Parallel(walking_.size(), [&](size_t b, size_t e) {
    for (size_t w = b; w < e; ++w) {
      const Agent& a = agents_[walking_[w]];
      for (size_t p = 0; p < locators; ++p)
        points_[w * locators + p] = Place(a, pair_centre_[pairs[p]]) +
                                    a.forward * (lead_ * a.stride) + a.up * (0.5 * lead_);
      for (size_t j = 0; j < per_agent; ++j) {
        Move& mv = moves_[w * per_agent + j];
        mv = Move{};
        mv.agent = walking_[w], mv.foot = stepping[j];
      }
    }
  });
  answers_.resize(points_.size());
  const Status s = Check(session_.Snap(terrain_, points_.data(), points_.size(), answers_.data()),
                         "snap locators", error);
  if (s != Status::kOk) return s;
  // 6 (end) and 7-8 in QueryFootholds; 9 (only the feet whose foothold was accepted) and 10-11
  // in ClearArcs. A foot whose arc cannot clear asks for its next foothold: its character goes
  // through both again.
  walkers_.resize(walking_.size());
  for (size_t w = 0; w < walking_.size(); ++w) walkers_[w] = w;
  body_frame_.assign(walking_.size(), std::numeric_limits<double>::quiet_NaN());
  while (!walkers_.empty()) {
    Status st = QueryFootholds(error);
    if (st == Status::kOk) st = ClearArcs(k, error);
    if (st != Status::kOk) return st;
  }
  for (size_t w = 0; w < walking_.size(); ++w)
    if (!std::isnan(body_frame_[w])) body_due_.emplace_back(walking_[w], body_frame_[w]);
  return KeyBodies(error);
}

}  // namespace

Vec3 TopCentre(const Vec3& lo, const Vec3& hi, const Vec3& up) {
  const Vec3 centre = (lo + hi) * 0.5;
  double top = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner{i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
    top = std::max(top, Dot(corner - centre, up));
  }
  return centre + up * top;
}

double StartSearchRadius(const Character& character) {
  return kStartSearchSteps * character.step_length;
}

double MaxStepTravel(const Character& character) {
  double scale = 0, drop = 0;
  for (const Attempt& a : kAttempts)
    scale = std::max(scale, a.scale), drop = std::max(drop, a.drop);
  return (scale + kFootholdTolerance) * character.step_length + drop * character.max_rise;
}

Status GenerateWalk(TerrainSession& session, TerrainHandle terrain, const Character& character,
                    const GenerateOptions& given, Walk* out, std::string* error) {
  // Directions are normalised here, exactly even for components near 1e300 (their squares
  // would overflow).
  GenerateOptions options = given;
  options.up = SafeNormalize(given.up);
  options.heading = SafeNormalize(given.heading);
  if (options.up == Vec3{}) {
    *error = "up must be a non-zero finite vector";
    return Status::kInvalidArgument;
  }
  if (options.heading == Vec3{}) {
    *error = "heading must be a non-zero finite vector";
    return Status::kInvalidArgument;
  }
  if (!IsFinite(options.start) || !(std::fabs(options.start_frame) <= kMaxStartFrame) ||
      !(options.fps > 0) || !(options.fps <= kMaxFps)) {
    std::ostringstream m;
    m << "start must be finite, the start frame within +-" << kMaxStartFrame
      << " and fps above 0 and at most " << kMaxFps;
    *error = m.str();
    return Status::kInvalidArgument;
  }
  // Waypoints within twice the terrain's coordinate range (the reach of its queries): farther,
  // squared distances to them overflow and the heading turned away from the goal.
  constexpr double kMaxWaypoint = 2 * terrain::kMaxCoordinate;
  for (size_t i = 0; i < options.path.size(); ++i) {
    const Vec3& p = options.path[i];
    if (!IsFinite(p) || std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > kMaxWaypoint) {
      std::ostringstream m;
      m << "path waypoint " << i + 1 << " (" << p.x << ", " << p.y << ", " << p.z
        << ") is not a finite point with each coordinate within +-" << kMaxWaypoint
        << " (the reach of terrain queries)";
      *error = m.str();
      return Status::kInvalidArgument;
    }
  }
  if (options.crowd < 1 || options.crowd > 1000000) {
    *error = "crowd must be from 1 to 1000000 characters";
    return Status::kInvalidArgument;
  }
  if (options.steps > 1000000) {
    *error = "steps must be at most 1000000";
    return Status::kInvalidArgument;
  }
  if (options.threads < 1) {
    *error = "threads must be at least 1";
    return Status::kInvalidArgument;
  }
  if (character.feet.empty() || character.gait.empty()) {
    *error = "the character has no feet or no gait";
    return Status::kInvalidArgument;
  }
  Walk walk;
  walk.fps = options.fps;
  std::vector<Agent> agents;
  Generator g(session, terrain, character, options, &agents, &walk);
  const Status s = g.Run(error);
  if (s != Status::kOk) return s;
  *out = std::move(walk);
  return Status::kOk;
}

}  // namespace footfall
