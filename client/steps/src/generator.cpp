// The step generator's run: setup, then passes of characters walked one step at a time, in
// parallel where the engine is in-process; and the public entry points of generator.h.
#include "step_generator.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>

#include "footfall/steps/foot_rotations.h"
#include "footfall/steps/linear_units.h"
#include "footfall/terrain/shown_text.h"

namespace footfall::steps_detail {

std::string Point(const Vec3& p) {
  Text o(4);
  o << std::fixed << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return o.str();
}

// `value` to 3 significant digits, or to as many more as it takes to differ from `limit`, which
// it breaks: "leans 100.0001 deg, more than max_slope_deg 100", never "leans 100 ... 100".
std::string Beyond(double value, double limit) {
  for (int digits = 3;; ++digits) {
    Text a(digits), b(digits);
    a << value, b << limit;
    if (a.str() != b.str() || digits >= 17) return a.str();
  }
}

// For ground facing away from the character's up (more than 120 degrees): what would make it
// so where the ground should face up (an underside is often just that: a log's, a beam's). A
// character that takes the terrain's normal as its up may also be wider than the beam or ledge
// it walks along, a foot reaching round its side.
std::string FacingDownHint(double slope_deg, bool aligned_to_normal) {
  if (!(slope_deg > 120)) return "";
  std::string hint = aligned_to_normal
                         ? "; it faces away from the character's up: if the ground there should "
                           "face it, the surface may be thinner"
                         : "; it faces down: if the ground there should face up, the surface may "
                           "be thinner";
  hint +=
      " than the terrain's sample spacing (resample at a separation below its thickness) or "
      "a mesh's faces may face inward";
  if (aligned_to_normal)
    hint +=
        "; or the character is wider than the beam or ledge it walks along, a foot reaching "
        "round its side";
  return hint;
}

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

Vec3 Generator::GaitCycleUp(const Vec3& before, const Vec3& after) {
  return Dot(before, after) > 0 ? NormalizeOr(before + after, after) : after;
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
  // A path walk without a step count that used every step it may take without reaching its goal
  // stopped short of what was asked: said as a stop (exit status 2), its keys kept.
  if (o_.steps < 0 && !o_.path.empty()) {
    for (Agent& a : agents_) {
      if (!a.walking || !a.stopped.empty() || a.path.empty() || Arrived(a)) continue;
      Text why(4);
      why << "the path's goal " << Point(a.path.back()) << " is still " << HowFar(a) << " after "
          << steps_ << " steps, the most a path walk takes without a step count (" << o_.names.steps
          << "; give one to walk farther)";
      Stop(a, steps_ + 1, why.str());
    }
  }
  // A path walk given its number of steps that took them all short of its goal did as asked
  // (no stop), but says how far the goal still is.
  walk_.notes = setup_notes_;
  if (!start_beyond_reach_.empty()) walk_.notes.push_back(start_beyond_reach_);
  if (o_.steps >= 0 && !o_.path.empty()) {
    for (Agent& a : agents_) {
      if (!a.walking || !a.stopped.empty() || a.path.empty() || Arrived(a)) continue;
      Text note(4);
      if (!a.id.empty()) note << a.id << ": ";
      note << "the path's goal " << Point(a.path.back()) << " is still " << HowFar(a)
           << " after the " << steps_ << " steps asked for (without a step count, "
           << o_.names.steps << ", a path walk goes on to its goal, up to " << kMaxPathSteps
           << " steps)";
      walk_.notes.push_back(note.str());
    }
  }
  // The walk's stop message: the engine's failure if it failed (it is no stop of the terrain's,
  // and may have stopped most of a crowd behind a few earlier stops), else the earliest stop
  // (the first character's among those of that step), and how many others stopped;
  // Walk::stops has every one, failures first.
  std::vector<const Agent*> stopped;
  for (const Agent& a : agents_)
    if (!a.stopped.empty()) stopped.push_back(&a);
  std::stable_sort(stopped.begin(), stopped.end(), [](const Agent* x, const Agent* y) {
    return x->failed != y->failed ? x->failed : x->stopped_step < y->stopped_step;
  });
  walk_.session_failed = !stopped.empty() && stopped[0]->failed;
  walk_.failed_stops = static_cast<size_t>(
      std::count_if(stopped.begin(), stopped.end(), [](const Agent* a) { return a->failed; }));
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
      return Status::kOk;  // (its steps left are not done: a bar stays where the failure left it)
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
  // What the copies found worth saying: the first character's note, as one pass would say it.
  for (Generator& g : copies) {
    if (g.start_beyond_reach_agent_ >= start_beyond_reach_agent_) continue;
    start_beyond_reach_agent_ = g.start_beyond_reach_agent_;
    start_beyond_reach_ = std::move(g.start_beyond_reach_);
  }
  return failure;
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
      Text why(4);
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
  //    wall, not into the corner), snapped to the terrain (one batch for every character). A
  //    biped's locator snapped back onto its feet's nose lands on the ground below (LandLocators).
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
  Status s = Check(session_.Snap(terrain_, points_.data(), points_.size(), answers_.data()),
                   "snap locators", error);
  landed_.assign(points_.size(), 0);
  if (s == Status::kOk && !c_.align_to_normal) s = LandLocators(error);
  if (s == Status::kOk && !c_.align_to_normal) s = ClimbLocators(error);
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

void Generator::Stop(Agent& a, int step, const std::string& why) {
  a.walking = false;
  Text m;
  m << "step " << step;
  if (!a.id.empty()) m << " of " << a.id;
  m << ": " << why << "; walk stopped, keys up to step " << step - 1 << " kept";
  a.stopped = m.str();
  a.stopped_step = step;
}

void Generator::StopPassAt(int k, const std::string& why) {
  const double f0 = StepFrame(k);
  for (size_t i = pass_begin_; i < pass_end_; ++i) {
    Agent& a = agents_[i];
    if (!a.walking) continue;
    UnkeyStep(a, f0);
    WalkTrack& body = walk_.tracks[a.first_track + c_.feet.size()];
    while (!body.keys.empty() && body.keys.back().frame > f0) body.keys.pop_back();
    if (body.rotations.size() > body.keys.size()) body.rotations.resize(body.keys.size());
    Stop(a, k + 1, why);
    a.failed = true;
  }
}

}  // namespace footfall::steps_detail

namespace footfall {

using namespace steps_detail;

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

namespace {

// How a message names an input: by its bare `field` for the command line's `flag` (as it always
// has), else by where it came from (a scene's file and field, a request's field).
std::string Subject(const std::string& name, const char* flag, const char* field) {
  return name == flag ? field : name;
}

}  // namespace

Status GenerateWalk(TerrainSession& session, TerrainHandle terrain, const Character& character,
                    const GenerateOptions& given, Walk* out, std::string* error) {
  std::string unwanted;  // a caller that passes no error string gets the status alone
  if (!error) error = &unwanted;
  // Directions are normalised here, exactly even for components near 1e300 (their squares
  // would overflow).
  GenerateOptions options = given;
  options.up = SafeNormalize(given.up);
  options.heading = SafeNormalize(given.heading);
  if (options.up == Vec3{}) {
    *error = Subject(given.names.up, "--up", "up") + " must be a non-zero finite vector";
    return Status::kInvalidArgument;
  }
  if (options.heading == Vec3{}) {
    *error =
        Subject(given.names.heading, "--heading", "heading") + " must be a non-zero finite vector";
    return Status::kInvalidArgument;
  }
  if (!WithinQueryReach(options.start)) {
    *error =
        (given.names.start == "--start" ? std::string("the start (--start)") : given.names.start) +
        " is too far from the terrain to snap (queries reach 1e15 from it)";
    return Status::kInvalidArgument;
  }
  if (!IsFinite(options.start) || !(std::fabs(options.start_frame) <= kMaxStartFrame) ||
      !(options.fps > 0) || !(options.fps <= kMaxFps)) {
    Text m;
    m << "start must be finite, the start frame within +-" << kMaxStartFrame
      << " and fps above 0 and at most " << kMaxFps;
    *error = m.str();
    return Status::kInvalidArgument;
  }
  for (size_t i = 0; i < options.path.size(); ++i) {
    const Vec3& p = options.path[i];
    if (!IsFinite(p) ||
        std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > kMaxWaypointCoordinate) {
      Text m;
      m << "path waypoint " << i + 1 << " (" << p.x << ", " << p.y << ", " << p.z
        << ") is not a finite point with each coordinate within +-" << kMaxWaypointCoordinate
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
  if (!options.unit.empty() && !(MetresPerLinearUnit(options.unit) > 0)) {
    *error = "unit '" + ShownText(options.unit) + "' is none of " + LinearUnitNames();
    return Status::kInvalidArgument;
  }
  Walk walk;
  walk.fps = options.fps;
  walk.unit = options.unit;
  std::vector<Agent> agents;
  Generator g(session, terrain, character, options, &agents, &walk);
  const Status s = g.Run(error);
  if (s != Status::kOk) return s;
  if (options.foot_rotations) AddFootRotations(&walk);
  *out = std::move(walk);
  return Status::kOk;
}

}  // namespace footfall
