// The step generator's sole fitting (3 and 8, end): for a character with a foot_length, a foot
// at the start or a foothold whose sole would hang past a stair's nose or stand in a riser
// moves along its tread.
#include "step_generator.h"

#include <algorithm>
#include <cmath>

namespace footfall::steps_detail {
namespace {

// Candidate places of a foothold whose sole misses ground: moved by 1/8, 2/8 ... of the sole.
constexpr int kSoleShifts = 4;
// A toe's nearest face turned against the sole by no more than this cosine (about 15 degrees
// from square to it: a tread's edge, or the face of the drop beyond it) does not stand ahead of
// the toe as a riser does; a toe no more than this share of the spacing behind that face's
// plane is not in it.
constexpr double kSquareToSole = 0.25;
constexpr double kBehind = 0.25;
// Snap points per foothold checked: its heel, its toe, and its toe raised by max_rise.
constexpr size_t kPerFoothold = 3;
// Snap points per candidate: its centre, heel and toe.
constexpr size_t kPerCandidate = 3;
// Snap points per sole checked around a sample (FitSoleWidths): its heel, toe and sides.
constexpr size_t kPerSole = 4;

// Whether a sole's end at `q`, whose nearest sample is h, stands on ground like the foothold's
// (normal `normal`): a sample within `near` of it facing alike. Past a stair's nose the nearest
// sample is the nose's edge, farther than that; inside a riser it is the riser, facing across.
bool SoleOnGround(const Vec3& q, const Foothold& h, const Vec3& normal, double near) {
  return h.status == Status::kOk && Distance(h.point, q) <= near &&
         Dot(h.normal, normal) >= kAlikeCos;
}

// The sole's direction at a foothold facing `normal`: the heading along its ground, or no
// direction (zero) for ground facing along the heading.
Vec3 SoleForward(const Vec3& forward, const Vec3& normal) {
  const Vec3 f = ProjectOnPlane(forward, normal);
  return Length2(f) >= 0.25 ? Normalize(f) : Vec3{};
}

// Which ways a foothold may move for its sole, from whether its heel and toe stand on ground:
// forward (1) when only the heel misses, back (2) when only the toe does, both (3) when both
// miss (a tread shorter than the sole, a narrow ledge), none (0) when the sole fits.
int SoleWays(bool heel_on, bool toe_on) { return (heel_on ? 0 : 1) | (toe_on ? 0 : 2); }
int SoleWayCount(int ways) { return (ways & 1) + (ways >> 1); }

// The places a foot at `end` may move to for its sole (direction f), the ways `ways` asks
// (SoleWays): shifted by 1/8 .. 4/8 of the sole, nearest first (forward before back at the
// same distance), each as its centre, heel and toe: kPerCandidate points a place, to `out`.
void SoleCandidates(const Vec3& end, const Vec3& f, int ways, double foot_length, Vec3* out) {
  const double half = 0.5 * foot_length;
  size_t at = 0;
  for (int k = 1; k <= kSoleShifts; ++k) {
    const double shift = foot_length * k / (2.0 * kSoleShifts);
    for (int way = 1; way <= 2; ++way) {
      if (!(ways & way)) continue;
      const Vec3 centre = end + f * (way == 1 ? shift : -shift);
      out[at++] = centre, out[at++] = centre - f * half, out[at++] = centre + f * half;
    }
  }
}

// Whether a candidate place (its centre, heel and toe `p`, their nearest samples `h`) stands
// on ground like `normal` under all three. The foot lands on the centre's sample, not on the
// centre: its heel and toe move with it, so theirs must have ground within `near` less that
// offset (a sole fitted up to the slack then hung past a nose by up to half a spacing more).
bool CandidateOnGround(const Vec3* p, const Foothold* h, const Vec3& normal, double near) {
  if (!SoleOnGround(p[0], h[0], normal, near)) return false;
  const double slack = near - Distance(h[0].point, p[0]);
  return SoleOnGround(p[1], h[1], normal, slack) && SoleOnGround(p[2], h[2], normal, slack);
}

// Whether a foot of foot f's character (`count` feet from a multiple of count) other than f
// stands on sample `index`.
bool TakenByOther(const Foothold* feet, size_t f, size_t count, uint32_t index) {
  const size_t c = f - f % count;
  for (size_t g = c; g < c + count; ++g)
    if (g != f && feet[g].status == Status::kOk && feet[g].index == index) return true;
  return false;
}

}  // namespace

Status Generator::SnapSole(const std::vector<Vec3>& points, std::vector<Foothold>* answers,
                           std::string* error) {
  answers->assign(points.size(), Foothold{});
  return Check(session_.Snap(terrain_, points.data(), points.size(), answers->data()), "snap sole",
               error);
}

Status Generator::FitSoles(std::string* error) {
  const size_t per_agent = walking_.empty() ? 0 : moves_.size() / walking_.size();
  const double half = 0.5 * c_.foot_length;
  const double near = 0.5 * gap_;  // the samples' spacing: the farthest ground under a point
  sole_moves_.clear(), sole_walker_.clear();
  for (size_t i = 0; i < walkers_.size(); ++i) {
    if (!all_done_[i]) continue;
    for (size_t m = walkers_[i] * per_agent; m < (walkers_[i] + 1) * per_agent; ++m) {
      Move& mv = moves_[m];
      if (!mv.done || mv.failed || mv.sole != 0) continue;
      // A step down past an edge nearer the other foot across the heading than the lined-up
      // limit, and nearer than the edge, gives way to the edge (on stairs walked at 30 to 60
      // degrees to the treads, feet crossed).
      if (mv.at_edge && GapToMate(mv, mv.end) < std::min(kMinPairGap, GapToMate(mv, mv.edge_point)))
        StandAtEdge(mv);
      mv.sole = 1;
      const Agent& a = agents_[mv.agent];
      if (mv.end != a.foot[mv.foot] && Length2(SoleForward(a.forward, mv.end_normal)) > 0)
        sole_moves_.push_back(m), sole_walker_.push_back(i);
    }
  }
  if (sole_moves_.empty()) return Status::kOk;
  // Heel and toe of each foothold, and the toe raised by max_rise along the feet's up: one
  // batch.
  const size_t n = sole_moves_.size();
  sole_points_.resize(kPerFoothold * n);
  Parallel(n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      const Move& mv = moves_[sole_moves_[i]];
      const Agent& a = agents_[mv.agent];
      const Vec3 f = SoleForward(a.forward, mv.end_normal);
      Vec3* p = &sole_points_[kPerFoothold * i];
      p[0] = mv.end - f * half, p[1] = mv.end + f * half, p[2] = p[1] + a.up * c_.max_rise;
    }
  });
  Status s = SnapSole(sole_points_, &sole_answers_, error);
  if (s != Status::kOk) return s;
  // The footholds whose sole misses ground, each with its candidates: the foothold moved the
  // ways its ends ask, nearest first (forward before back at the same distance).
  sole_ways_.assign(n, 0);
  sole_first_.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    Move& mv = moves_[sole_moves_[i]];
    const Vec3& normal = mv.end_normal;
    const Vec3* p = &sole_points_[kPerFoothold * i];
    const Foothold* h = &sole_answers_[kPerFoothold * i];
    const Foothold& toe = h[1];
    sole_ways_[i] =
        SoleWays(SoleOnGround(p[0], h[0], normal, near), SoleOnGround(p[1], toe, normal, near));
    // A toe whose ground max_rise above it is a face across the foothold's (not the next tread)
    // is at a wall, not a riser: the foot stands at the wall's foot as found (its next step
    // finds the wall; kept back from it, a biped stood before a wall step after step instead of
    // stopping there).
    if ((sole_ways_[i] & 2) && h[2].status == Status::kOk && Dot(h[2].normal, normal) < kAlikeCos)
      sole_ways_[i] &= 1;
    // A foot stepping to the edge of the ground it stands on (level with it, on a step not
    // aimed up: a riser ahead draws the target up), its toe over the drop beyond (its nearest
    // sample that edge's or the drop's face, and not behind it; a riser ahead faces against
    // the sole), stands there. Unless its other foot stands higher (it would step two treads
    // below it), it tries stepping down past the edge first, its whole step aimed down, and
    // stands at the edge only if that is refused (StandAtEdge). (Moved back from the edge, it
    // found the same edge at its next step, short down steep stairs, and shuffled to it: two
    // steps a tread.)
    const Agent& a = agents_[mv.agent];
    const Vec3 f = SoleForward(a.forward, normal);
    if (sole_ways_[i] == 2 && toe.status == Status::kOk && Dot(mv.step, a.up) <= 0 &&
        Dot(toe.normal, f) >= -kSquareToSole &&
        Dot(p[1] - toe.point, toe.normal) >= -kBehind * near &&
        std::fabs(Dot(mv.end - a.foot[mv.foot], a.up)) <= near) {
      sole_ways_[i] = 0;
      const int mate = mate_[mv.foot];
      if (mv.attempts <= kFirstDownAttempt &&
          (mate < 0 || Dot(a.foot[mate] - mv.end, a.up) <= near)) {
        mv.at_edge = true, mv.edge_point = mv.end, mv.edge_normal = mv.end_normal;
        mv.done = false, mv.sole = 0, mv.attempts = kFirstDownAttempt;
        all_done_[sole_walker_[i]] = 0;
      }
    }
    sole_first_[i + 1] = sole_first_[i] + kPerCandidate * kSoleShifts * SoleWayCount(sole_ways_[i]);
  }
  if (sole_first_[n] == 0) return FitMoveSoleWidths(error);
  // The candidates' centres, heels and toes: one batch.
  sole_points_.resize(sole_first_[n]);
  Parallel(n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      if (sole_ways_[i] == 0) continue;
      const Move& mv = moves_[sole_moves_[i]];
      const Vec3 f = SoleForward(agents_[mv.agent].forward, mv.end_normal);
      SoleCandidates(mv.end, f, sole_ways_[i], c_.foot_length, &sole_points_[sole_first_[i]]);
    }
  });
  s = SnapSole(sole_points_, &sole_answers_, error);
  if (s != Status::kOk) return s;
  // The nearest candidate whose centre snaps onto ground like the foothold's, with ground under
  // its heel and toe, that Judge would accept as it did the foothold (rise, slope, no nearer
  // its mate across the heading than the lined-up limit or than the foothold), and that keeps
  // at least half the foothold's way along the sole from where the foot stands (a sample aside
  // is no step). (Judge's progress, half the step aimed, refused most places back from a nose
  // that a step aimed down past it had reached.)
  Parallel(n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      Move& mv = moves_[sole_moves_[i]];
      const Vec3 f = SoleForward(agents_[mv.agent].forward, mv.end_normal);
      const double way = Dot(mv.end - agents_[mv.agent].foot[mv.foot], f);
      for (size_t at = sole_first_[i]; at < sole_first_[i + 1]; at += kPerCandidate) {
        const Foothold& h = sole_answers_[at];
        if (!CandidateOnGround(&sole_points_[at], &sole_answers_[at], mv.end_normal, near) ||
            !KeepsSoleShift(mv, h, f, way))
          continue;
        mv.end = h.point, mv.end_normal = h.normal, mv.sole = 2;
        break;
      }
    }
  });
  return FitMoveSoleWidths(error);
}

bool Generator::KeepsSoleShift(const Move& mv, const Foothold& h, const Vec3& f, double way) const {
  const Agent& a = agents_[mv.agent];
  const Vec3& foot = a.foot[mv.foot];
  return Dot(h.point - foot, f) >= 0.5 * way &&
         std::fabs(Dot(h.point - foot, a.up)) <= c_.max_rise * (1 + kRiseRounding) &&
         Dot(h.normal, a.up) >= cos_max_slope_ &&
         GapToMate(mv, h.point) >= std::min(kMinPairGap, GapToMate(mv, mv.end));
}

Status Generator::FitMoveSoleWidths(std::string* error) {
  if (!(c_.foot_width > 0)) return Status::kOk;
  // The footholds FitSoles checked that stand (not asked again aimed down).
  std::vector<size_t> fitted;
  std::vector<Foothold> holds;
  std::vector<Vec3> forward;
  std::vector<double> way;
  for (size_t m : sole_moves_) {
    const Move& mv = moves_[m];
    if (!mv.done || mv.failed) continue;
    const Vec3 f = SoleForward(agents_[mv.agent].forward, mv.end_normal);
    if (Length2(f) == 0) continue;
    Foothold h;
    h.status = Status::kOk, h.point = mv.end, h.normal = mv.end_normal;
    fitted.push_back(m), holds.push_back(h), forward.push_back(f);
    way.push_back(Dot(mv.end - agents_[mv.agent].foot[mv.foot], f));
  }
  if (fitted.empty()) return Status::kOk;
  const Status s = FitSoleWidths(
      &holds, forward,
      [&](size_t i, const Foothold& h) {
        return KeepsSoleShift(moves_[fitted[i]], h, forward[i], way[i]);
      },
      error);
  if (s != Status::kOk) return s;
  for (size_t i = 0; i < fitted.size(); ++i) {
    Move& mv = moves_[fitted[i]];
    if (holds[i].point == mv.end) continue;
    mv.end = holds[i].point, mv.end_normal = holds[i].normal, mv.sole = 2;
  }
  return Status::kOk;
}

Status Generator::FitSoleWidths(std::vector<Foothold>* holds, const std::vector<Vec3>& forward,
                                const std::function<bool(size_t, const Foothold&)>& keeps,
                                std::string* error) {
  const size_t n = holds->size();
  const double near = 0.5 * gap_;
  // The sole's heel, toe and sides around a middle at p (`left` across it): kPerSole points.
  auto sole = [&](const Vec3& p, const Vec3& f, const Vec3& left, Vec3* out) {
    out[0] = p - f * (0.5 * c_.foot_length), out[1] = p + f * (0.5 * c_.foot_length);
    out[2] = p + left * (0.5 * c_.foot_width), out[3] = p - left * (0.5 * c_.foot_width);
  };
  // Each sole's sides at its middle: one batch.
  std::vector<Vec3> left(n), points(2 * n);
  for (size_t i = 0; i < n; ++i) {
    const Foothold& h = (*holds)[i];
    left[i] = Normalize(Cross(h.normal, forward[i]));
    points[2 * i] = h.point + left[i] * (0.5 * c_.foot_width);
    points[2 * i + 1] = h.point - left[i] * (0.5 * c_.foot_width);
  }
  std::vector<Foothold> answers;
  Status s = SnapSole(points, &answers, error);
  if (s != Status::kOk) return s;
  // The soles with one side off the ground: their places moved toward the other side, nearest
  // first (one batch).
  std::vector<double> toward(n, 0);  // +1: toward the left, -1: the right, 0: fits or stays
  std::vector<size_t> moved;
  for (size_t i = 0; i < n; ++i) {
    const Vec3& normal = (*holds)[i].normal;
    const bool left_on = SoleOnGround(points[2 * i], answers[2 * i], normal, near);
    const bool right_on = SoleOnGround(points[2 * i + 1], answers[2 * i + 1], normal, near);
    if (left_on != right_on) toward[i] = left_on ? 1 : -1, moved.push_back(i);
  }
  if (moved.empty()) return Status::kOk;
  std::vector<Vec3> places;
  for (size_t i : moved)
    for (int k = 1; k <= kSoleShifts; ++k)
      places.push_back((*holds)[i].point +
                       left[i] * (toward[i] * c_.foot_width * k / (2.0 * kSoleShifts)));
  std::vector<Foothold> landed;
  s = SnapSole(places, &landed, error);
  if (s != Status::kOk) return s;
  // The sole around each sample a place lands on (the foot stands on the sample, not the
  // place), for the places on ground like the foothold's that keeps accepts: one batch.
  std::vector<size_t> first(places.size() + 1, 0);
  points.clear();
  for (size_t m = 0; m < moved.size(); ++m) {
    const size_t i = moved[m];
    for (int k = 0; k < kSoleShifts; ++k) {
      const size_t at = m * kSoleShifts + k;
      const Foothold& h = landed[at];
      if (SoleOnGround(places[at], h, (*holds)[i].normal, near) && keeps(i, h)) {
        points.resize(points.size() + kPerSole);
        sole(h.point, forward[i], left[i], &points[points.size() - kPerSole]);
      }
      first[at + 1] = points.size();
    }
  }
  if (points.empty()) return Status::kOk;
  s = SnapSole(points, &answers, error);
  if (s != Status::kOk) return s;
  for (size_t m = 0; m < moved.size(); ++m) {
    const size_t i = moved[m];
    const Vec3 normal = (*holds)[i].normal;
    for (int k = 0; k < kSoleShifts; ++k) {
      const size_t at = m * kSoleShifts + k;
      if (first[at + 1] == first[at]) continue;  // off the ground, or refused
      bool on = true;
      for (size_t q = first[at]; on && q < first[at + 1]; ++q)
        on = SoleOnGround(points[q], answers[q], normal, near);
      if (!on) continue;
      (*holds)[i] = landed[at];
      break;
    }
  }
  return Status::kOk;
}

Status Generator::FitStartSoles(Foothold* feet, size_t total, size_t count, const Agent* agents,
                                std::string* error) {
  if (!(c_.foot_length > 0) || count == 0) return Status::kOk;
  const double half = 0.5 * c_.foot_length;
  const double near = 0.5 * gap_;
  // The heel and toe of every foot with a direction on its ground: one batch.
  std::vector<size_t> checked;
  std::vector<Vec3> forward, points;
  for (size_t f = 0; f < total; ++f) {
    if (feet[f].status != Status::kOk) continue;
    const Vec3 fwd = SoleForward(agents[f / count].forward, feet[f].normal);
    if (Length2(fwd) == 0) continue;
    checked.push_back(f), forward.push_back(fwd);
    points.push_back(feet[f].point - fwd * half), points.push_back(feet[f].point + fwd * half);
  }
  if (checked.empty()) return Status::kOk;
  std::vector<Foothold> answers;
  Status s = SnapSole(points, &answers, error);
  if (s != Status::kOk) return s;
  // The candidates of the feet whose sole misses ground: one more batch.
  std::vector<size_t> first(checked.size() + 1, 0);
  std::vector<int> ways(checked.size());
  for (size_t i = 0; i < checked.size(); ++i) {
    const Vec3& normal = feet[checked[i]].normal;
    ways[i] = SoleWays(SoleOnGround(points[2 * i], answers[2 * i], normal, near),
                       SoleOnGround(points[2 * i + 1], answers[2 * i + 1], normal, near));
    first[i + 1] = first[i] + kPerCandidate * kSoleShifts * SoleWayCount(ways[i]);
  }
  if (first.back() == 0) return FitStartSoleWidths(feet, count, checked, forward, error);
  points.resize(first.back());
  for (size_t i = 0; i < checked.size(); ++i)
    if (ways[i] != 0)
      SoleCandidates(feet[checked[i]].point, forward[i], ways[i], c_.foot_length,
                     &points[first[i]]);
  s = SnapSole(points, &answers, error);
  if (s != Status::kOk) return s;
  // The nearest candidate with ground like the foot's under its centre, heel and toe, on a
  // sample no other foot of its character stands on.
  for (size_t i = 0; i < checked.size(); ++i) {
    const size_t f = checked[i];
    for (size_t at = first[i]; at < first[i + 1]; at += kPerCandidate) {
      const Foothold& h = answers[at];
      if (!CandidateOnGround(&points[at], &answers[at], feet[f].normal, near)) continue;
      if (TakenByOther(feet, f, count, h.index)) continue;
      feet[f] = h;
      break;
    }
  }
  return FitStartSoleWidths(feet, count, checked, forward, error);
}

Status Generator::FitStartSoleWidths(Foothold* feet, size_t count,
                                     const std::vector<size_t>& checked,
                                     const std::vector<Vec3>& forward, std::string* error) {
  if (!(c_.foot_width > 0) || checked.empty()) return Status::kOk;
  std::vector<Foothold> holds(checked.size());
  for (size_t i = 0; i < checked.size(); ++i) holds[i] = feet[checked[i]];
  // On a sample no other foot of its character stands on.
  const Status s = FitSoleWidths(
      &holds, forward,
      [&](size_t i, const Foothold& h) { return !TakenByOther(feet, checked[i], count, h.index); },
      error);
  if (s != Status::kOk) return s;
  for (size_t i = 0; i < checked.size(); ++i) feet[checked[i]] = holds[i];
  return Status::kOk;
}

}  // namespace footfall::steps_detail
