// The step generator's swing arcs and keys (9-11): arcs checked against the terrain and raised
// until they clear it, then foot keys (start, mid, end) and body keys, bodies raised clear of
// the terrain.
#include "step_generator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace footfall::steps_detail {
namespace {

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

// True when the foothold `foot` stands against h's face: in front of its plane, nearer than
// `near`, on ground unlike it (a toe at a riser).
bool StandsAgainst(const Foothold& h, const Vec3& foot, const Vec3& foot_normal, double near) {
  const double kept = Dot(foot - h.point, h.normal);
  return Dot(h.normal, foot_normal) < kAlikeCos && kept >= 0 && kept <= near;
}

// The clearance an arc point must keep from h, its nearest sample: `nominal`, or, when the
// arc's foothold `foot` there stands against h's face (`against`: StandsAgainst), no more than
// half of what the foot itself keeps from that plane.
double ClearanceNeeded(double nominal, const Foothold& h, const Vec3& foot, bool against) {
  return against ? std::min(nominal, 0.5 * Dot(foot - h.point, h.normal)) : nominal;
}

}  // namespace

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
          mv.hooks = 0;
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
          // The face that half's foothold stands against, if any point of the half is near it.
          Vec3 face[2] = {Vec3{}, Vec3{}};
          const size_t first = arc_first_[i], checks = arc_first_[i + 1] - first;
          for (size_t j = 0; j < checks; ++j) {
            const Foothold& h = arc_answers_[first + j];
            const double s = ArcS(j, checks);
            if (h.status != Status::kOk) continue;
            const int half = s > 0.5;
            const double nominal = c_.step_height * (1 - std::fabs(2 * s - 1));
            const Vec3& foot = half ? mv.end : a.foot[mv.foot];
            const Vec3& foot_normal = half ? mv.end_normal : a.foot_normal[mv.foot];
            const bool against = StandsAgainst(h, foot, foot_normal, c_.step_height);
            const double need = ClearanceNeeded(kClearanceFraction * nominal, h, foot, against);
            if (against) face[half] = h.normal;
            if (Clearance(arc_points_[first + j], h, gap_, a.up) < need) {
              low[half] = true;
              wall[half] |= need < kClearanceFraction * nominal;
            }
          }
          if (!low[0] && !low[1]) continue;
          // Raised all it may be, one half still low by its foothold standing against a face
          // (a foot landing at a riser's foot from the nose above it drops past that nose): the
          // mid key hooks out from the face over that foothold, up to kMaxHooks times higher.
          const int hook = low[0] ? 0 : 1;
          if (round + 1 >= kMaxRaises && low[hook] != low[1 - hook] && mv.hooks < kMaxHooks &&
              Length2(face[hook]) > 0) {
            const Vec3& at = hook == 0 ? a.foot[mv.foot] : mv.end;
            const Vec3& other = hook == 0 ? mv.end : a.foot[mv.foot];
            const double height = std::max(0.0, Dot(other - at, mv.mid_normal)) +
                                  0.5 * c_.step_height * (++mv.hooks + 1);
            const Vec3 out = NormalizeOr(ProjectOnPlane(face[hook], mv.mid_normal), Vec3{});
            mv.mid = at + mv.mid_normal * height + out * (kHookOut * height);
            verdict_[i] = 1, raised_[g] = 1;
            continue;
          }
          if (round + 1 >= kMaxRaises) {
            // The foot asks for another foothold (its next try), or gives up after the last.
            if (KeepsReason(mv, false)) {
              Text why(3);
              why << "the swing arc to " << Point(mv.end)
                  << " cannot clear the terrain (mid key raised " << kMaxRaises * kRaise
                  << " step heights)";
              mv.reason = why.str(), mv.reason_is_gap = false;
            }
            mv.done = false;
            Reopen(mv);
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
  const double f0 = StepFrame(k), f_mid = StepFrame(k + 0.5), f1 = StepFrame(k + 1);
  const size_t m = w * per_agent, e = m + per_agent;
  Agent& a = agents_[walking_[w]];
  // The window slides: it starts again wherever the body gets half a step from its start, so a
  // body that settles stops a window after it settled (fixed windows let one stay nearly two).
  if (a.window_step < 0 || Distance(a.ground, a.window_from) >= 0.5 * c_.step_length) {
    a.window_from = a.ground, a.window_step = k;
  } else if (k - a.window_step >= window_steps_) {
    Text why(4);
    why << "no way forward from " << Point(a.window_from) << ": the body has stayed within half "
        << "a step of it for " << window_steps_ << " steps (a dead end)";
    Stop(a, k + 1, why.str());
    return;
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
  const Vec3 fitted = BodyUp(a.up, a.foot);
  a.body_up = GaitCycleUp(a.fitted_up, fitted);
  a.fitted_up = fitted;
  a.forward = TangentForward(a.forward, a.forward, old_up, a.up);
  body_frame_[w] = f1;  // keyed by KeyBodies at the end of the step
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

void Generator::KeyStart(const Agent& a) {
  // 4 (end). Every foot and the body keyed planted at the start frame.
  const Vec3 body = a.ground + a.body_up * c_.body_height;
  const size_t index = static_cast<size_t>(&a - agents_.data());
  for (size_t f = 0; f < c_.feet.size(); ++f) {
    KeyFoot(a, static_cast<int>(f), o_.start_frame, KeyPhase::kEnd, a.foot[f], a.foot_normal[f]);
    // Feet snap to the nearest samples: samples far apart for the character may leave one
    // beyond reach, which the steps never do. Said once, for the first such character (the walk
    // likely stops soon).
    const double dist = Distance(a.foot[f], body);
    if (index < start_beyond_reach_agent_ && dist > c_.reach * (1 + 1e-9)) {
      start_beyond_reach_agent_ = index;
      Text note(3);
      if (!a.id.empty()) note << a.id << ": ";
      note << "at the start, foot " << c_.feet[f].name << " stands " << dist
           << " from the body, beyond reach " << c_.reach << ": the terrain's samples (about "
           << 0.5 * gap_
           << " apart) are too far apart for this character; resample the terrain finer "
              "(footfall terrain convert --character) or raise reach";
      start_beyond_reach_ = note.str();
    }
  }
  body_due_.emplace_back(index, o_.start_frame);
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
    // Terrain no higher than step_height above a foot is stepped over, not walked under: a
    // kerb 5 cm tall between the feet, its top crossing the spine, stopped the walk as an
    // overhang (a swing arc clears step_height; a slab over the feet is higher).
    const double low_enough = std::max(gap_, c_.step_height);
    auto across = [&](const Foothold& h) {
      if (h.status != Status::kOk) return false;
      const Vec3 d = h.point - a.ground;
      if (Dot(d, a.body_up) >= top || Length(ProjectOnPlane(d, a.body_up)) > gap_) return false;
      for (const Vec3& foot : a.foot)
        if (Dot(h.point - foot, a.body_up) <= low_enough) return false;
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
    Text why;
    why << "no room for the body at " << Point(body_points_[spine_first_[i + 1] - 1])
        << ": the terrain at " << Point(crossing->point)
        << " lies between it and its feet (an overhang or a ceiling lower than body_height)";
    // The body is keyed where its step ends: step `step` (from 1) ends at StepFrame(step).
    const int step = static_cast<int>(std::lround((frame - o_.start_frame) / c_.frames_per_step));
    UnkeyStep(a, StepFrame(step - 1));
    Stop(a, step, why.str());
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

}  // namespace footfall::steps_detail
