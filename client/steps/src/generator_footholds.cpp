// The step generator's steering and footholds (5-8): the heading turned along the path, the
// target locators, the foothold queries of every moving foot in one batch, and their judging
// (slope, rise, reach, side).
#include "step_generator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "footfall/terrain/shown_text.h"

namespace footfall::steps_detail {
namespace {

// The least outward shift of a lined-up foot's retry, as a share of gap_ (twice the sample
// spacing): half a spacing, toward the sample on the foot's own side.
constexpr double kNearestOutward = 0.25;
// The gap from its mate, as a share of their rest gap, that a lined-up foot's retry aims at
// (the rest gap itself pushed the downhill foot of a biped turning on stairs over the nose it
// walked along more often, and made more steps two treads down: 56 walks of 600 against 53).
constexpr double kOutwardGoal = 0.75;

// A lined-up foot's outward retry aimed farther than `least` that was refused or did no
// better: asked again `least` outward (true), at the sample on the foot's own side.
bool NearerOutward(Move& mv, double least) {
  if (mv.outward <= least) return false;
  mv.outward = least;
  --mv.attempts;  // the same attempt again
  return true;
}

// The distance from p to the box [lo, hi] (0 inside).
double BoxDistance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 out{std::max({lo.x - p.x, 0.0, p.x - hi.x}), std::max({lo.y - p.y, 0.0, p.y - hi.y}),
                 std::max({lo.z - p.z, 0.0, p.z - hi.z})};
  return Length(out);
}

}  // namespace

void Reopen(Move& mv) {
  // (A lined-up foothold's arc may clear, or it be in reach; so may the foothold as found.)
  if (mv.outward_kept || mv.sole == 2) --mv.attempts;
  mv.outward = mv.outward_kept ? -1 : 0;
  mv.lined_up = mv.outward_kept = false;
  mv.sole = mv.sole == 2 || mv.sole < 0 ? -1 : 0;
}

bool Generator::Nearing(Agent& a, int k) const {
  if (a.path.empty()) return true;
  // Coming nearer as Remaining measures it, or seen from above: on ground steeper than a floor
  // a waypoint off the terrain is measured across a's up, where a 2D path's height (300 m
  // below a 65-degree ramp) outweighs the way walked, and a hexapod coming 2.4 m nearer seen
  // from above was stopped for "no way".
  const double d = Remaining(a, a.waypoint);
  const double level = Length(ProjectOnPlane(a.path[a.waypoint] - a.ground, world_up_));
  const double quarter = 0.25 * c_.step_length;
  if (a.nearest_waypoint != a.waypoint || d < a.nearest - quarter ||
      level < a.nearest_level - quarter) {
    if (a.nearest_waypoint != a.waypoint || d < a.nearest - quarter) a.nearest = d;
    if (a.nearest_waypoint != a.waypoint || level < a.nearest_level - quarter)
      a.nearest_level = level;
    a.nearest_waypoint = a.waypoint, a.nearest_step = k;
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

bool Generator::OnFloor(const Agent& a) const {
  return Dot(a.up, world_up_) >= std::cos(Radians(kFloorUpDeg));
}

Vec3 Generator::ToPathPoint(const Agent& a, const Vec3& p, bool on_terrain) const {
  Vec3 to = p - a.ground;
  if (!on_terrain && OnFloor(a)) to -= world_up_ * Dot(to, world_up_);
  return to;
}

Vec3 Generator::OnGround(const Agent& a, const Vec3& to, bool on_terrain) const {
  // (Laid along the world up also near a waypoint on the terrain, an octopod going round the
  // foot of a stair's riser to a goal there took a way that stopped at the riser.)
  const bool level = !on_terrain || (std::fabs(Dot(to, world_up_)) <= 0.5 * Length(to) &&
                                     Length(to) > 10 * c_.step_length);
  if (!level || !OnFloor(a)) return ProjectOnPlane(to, a.up);
  return to - world_up_ * (Dot(to, a.up) / Dot(world_up_, a.up));  // (the dot is >= 0.5)
}

double Generator::Remaining(const Agent& a, size_t i) const {
  const Vec3 to = ToWaypoint(a, i);
  if (OnTerrain(a, i) || OnFloor(a)) return Length(to);  // (on a floor, `to` is level)
  return Length(ProjectOnPlane(to, a.up));
}

bool Generator::Reached(const Agent& a, size_t i) const {
  const Vec3 to = ToWaypoint(a, i);
  const double along = Dot(to, a.up), radius = Radius(a, i);
  // Off the terrain, on a floor, `to` is level already: measured as it is, not shortened
  // across a's up as the ground tilts (Remaining).
  const Vec3 across = !OnTerrain(a, i) && OnFloor(a) ? to : to - a.up * along;
  if (Length2(across) > radius * radius) return false;
  // On the terrain: no farther below the ground than the radius, nor above it than the radius
  // over the body's height (the feet's centroid lies inside a convex nose or ridge they stand
  // around: an octopod on the Spot mesh's nose came within 2 cm of its goal with its body,
  // never within its radius with its ground, and turned about it until it stopped).
  return !OnTerrain(a, i) || (along >= -radius && along <= radius + c_.body_height);
}

double Generator::StrideToward(const Vec3& to, const Vec3& forward, double radius) const {
  // A waypoint inside the circle the body turns on at full stride (beside or behind it, nearer
  // than the turn allows) would be circled for ever: the steps shorten so that the circle the
  // body turns on, tangent to the heading, runs through the waypoint, and with the waypoint
  // behind that heading the character turns on the spot. One the heading already passes
  // within `radius` of (where it is reached) is walked to at full stride: a character turning
  // 0.1 degrees a step, whose circle is some 200 m wide, took a goal straight ahead but a few
  // centimetres aside, where its feet had snapped, for one inside that circle; its strides
  // shrank to nothing and it shuffled sideways for 1000 steps.
  const double ahead = Dot(to, forward);
  const double aside = Length(to - forward * ahead);
  if (ahead > 0 && aside <= radius) return 1;
  const double through = Length2(to) / (2 * aside);  // that circle's radius (inf: no circle)
  if (through >= turn_radius_) return 1;
  // A stride shorter than the terrain's samples lie apart cannot be walked as asked: the feet
  // step in place or a whole sample on, and the body circles wider than the circle through the
  // waypoint (a biped turning 1 degree a step circled a corner 0.6 m off for 370 steps, never
  // within its half step of it). It turns on the spot instead, until the waypoint lies ahead.
  const double stride = through / turn_radius_;
  return ahead > 0 && stride * c_.step_length >= 0.5 * gap_ ? stride : 0;
}

std::string Generator::HowFar(const Agent& a) const {
  // Four significant digits, and every digit before the point (not 1.198e+04).
  auto text = [](double d) {
    Text t(std::max(4, d >= 1 ? static_cast<int>(std::floor(std::log10(d))) + 1 : 0));
    t << d;
    return t.str();
  };
  const std::string straight = text(Remaining(a, a.path.size() - 1));
  if (a.waypoint + 1 >= a.path.size()) return straight + " away";
  return text(PathLeft(a)) + " away along the path (" + straight + " in a straight line)";
}

double Generator::PathLeft(const Agent& a) const {
  double left = Remaining(a, a.waypoint);
  for (size_t i = a.waypoint; i + 1 < a.path.size(); ++i)
    left += Distance(a.path[i], a.path[i + 1]);
  return left;
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
  const Vec3 to = OnGround(a, ToWaypoint(a, a.waypoint), OnTerrain(a, a.waypoint));
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
    a.stride = StrideToward(to, a.forward, Radius(a, a.waypoint));
    return;
  }
  double best_gap = -std::numeric_limits<double>::infinity();
  Vec3 best_forward = a.forward;
  double best_stride = 1;
  for (int eighths = kTurnShares; eighths >= 0; --eighths) {
    const Vec3 forward = Normalize(RotateAround(a.forward, a.up, turn * eighths / kTurnShares));
    const double stride = StrideToward(to, forward, Radius(a, a.waypoint));
    const double gap = PairGap(a, forward, stride, group);
    if (gap > best_gap) best_gap = gap, best_forward = forward, best_stride = stride;
    if (gap >= kMinPairGap) {
      best_forward = forward, best_stride = stride;
      break;
    }
  }
  a.forward = best_forward, a.stride = best_stride;
}

bool Generator::ClimbedAside(const Foothold& h, const Vec3& placed, const Agent& a, double lean,
                             double off) const {
  // Climbing stairs at a slant, the place lies over the tread the feet stand on, nearer the
  // nose of the next one up beside the heading: a biped took a tread a step whatever its
  // heading, its way bending up the flight (12 degrees to the treads walked at 24). Onto ground
  // leaning little across the heading, above the rest height (lead/2 below the place) by more
  // than a sample spacing, aside of the place by more than a spacing and along the heading by
  // no more than half that (or a spacing: the samples' lattice).
  const double spacing = 0.5 * gap_;
  const double along = std::fabs(Dot(h.point - placed, a.forward));
  return lean < kFlatLean && std::fabs(off) > spacing &&
         along <= std::max(0.5 * std::fabs(off), spacing) &&
         Dot(h.point - placed, a.up) > spacing - 0.5 * lead_;
}

Status Generator::SnapLandPoints(std::string* error) {
  land_answers_.resize(land_points_.size());
  return Check(
      session_.Snap(terrain_, land_points_.data(), land_points_.size(), land_answers_.data()),
      "snap locators", error);
}

Status Generator::LandLocators(std::string* error) {
  const size_t locators = pairs_of_group_[group_].size();
  const double spacing = 0.5 * gap_;
  // Lines along the up at kLandLines points from the snap to the place (the last through the
  // place), each probed down from the place's rest height to max_rise below it, a point every
  // sample spacing (at most 33).
  const int per_line = std::clamp(static_cast<int>(std::ceil(c_.max_rise / spacing)), 1, 32);
  const size_t line = static_cast<size_t>(per_line) + 1, lines = kLandLines * line;
  const double drop = c_.max_rise / per_line;
  land_points_.clear(), land_locator_.clear();
  for (size_t l = 0; l < points_.size(); ++l) {
    const Agent& a = agents_[walking_[l / locators]];
    // Snapped back toward the body, aside of that line by more than a sample spacing, onto
    // ground no lower than the place's rest height (less a spacing): on ground reaching out
    // over lower ground ahead (the nose of the tread the feet stand on), or under it. (Snapped
    // back onto lower ground, a step down is found: the next nose down a flight.)
    const Vec3 aside = ProjectOnPlane(answers_[l].point - points_[l], a.up);
    if (Length(aside) <= spacing || Dot(aside, a.forward) >= 0) continue;
    const double rest_height = Dot(points_[l], a.up) - 0.5 * lead_;
    if (Dot(answers_[l].point, a.up) < rest_height - spacing) continue;
    land_locator_.push_back(l);
    for (int q = 1; q <= kLandLines; ++q) {
      const Vec3 top =
          points_[l] + aside * (1 - static_cast<double>(q) / kLandLines) - a.up * (0.5 * lead_);
      for (int j = 0; j <= per_line; ++j) land_points_.push_back(top - a.up * (drop * j));
    }
  }
  if (land_points_.empty()) return Status::kOk;
  if (const Status s = SnapLandPoints(error); s != Status::kOk) return s;
  for (size_t i = 0; i < land_locator_.size(); ++i) {
    const size_t l = land_locator_[i];
    const Agent& a = agents_[walking_[l / locators]];
    const Vec3& placed = points_[l];
    const double rest_height = Dot(placed, a.up) - 0.5 * lead_;
    const double snapped_height = Dot(answers_[l].point, a.up);
    // Each line's ground: the first probe's sample straight below it, near the line (within
    // 1.5 spacings, for samples spread unevenly), not above it, facing the up; lower than the
    // snapped locator by a spacing and not above the rest height by more (ground rising ahead
    // is the snap's to find).
    const Foothold* ground[kLandLines] = {};
    double highest = -std::numeric_limits<double>::infinity();
    for (int q = 0; q < kLandLines; ++q) {
      for (size_t j = i * lines + q * line; j < i * lines + (q + 1) * line; ++j) {
        const Foothold& h = land_answers_[j];
        if (h.status != Status::kOk || Dot(h.normal, a.up) < cos_max_slope_) continue;
        const Vec3 off = h.point - land_points_[j];
        if (Length(ProjectOnPlane(off, a.up)) > 0.75 * gap_ || Dot(off, a.up) > 0.5 * spacing)
          continue;
        const double height = Dot(h.point, a.up);
        if (height > snapped_height - spacing || height > rest_height + spacing) continue;
        ground[q] = &h;
        highest = std::max(highest, height);
        break;
      }
    }
    // Over lower ground (the place over a tread below, not inside the step the snap lies on
    // the riser of), the first ground down from the snap (the next tread, not the one after
    // it where the place lies beyond a shallow tread), as near the place as it reaches. The
    // place's line without ground is over lower ground still when each of its points down to a
    // spacing above that ground lies in front of the face nearest it, not behind it by more than
    // a quarter spacing (in the air over a tread more than max_rise below: a biped heading down
    // 30 to 38 cm risers at 40 to 60 degrees to the treads walked along the top tread).
    if (!ground[kLandLines - 1]) {
      bool in_air = false;  // and at least one point checked
      for (size_t j = i * lines + (kLandLines - 1) * line; j < (i + 1) * lines; ++j) {
        const Foothold& h = land_answers_[j];
        if (Dot(land_points_[j], a.up) < highest + spacing) break;
        in_air =
            h.status == Status::kOk && Dot(land_points_[j] - h.point, h.normal) > -0.25 * spacing;
        if (!in_air) break;
      }
      if (!in_air) continue;
    }
    for (int q = kLandLines - 1; q >= 0; --q) {
      if (ground[q] && Dot(ground[q]->point, a.up) >= highest - spacing) {
        answers_[l] = *ground[q], landed_[l] = 1;
        break;
      }
    }
  }
  return Status::kOk;
}

Status Generator::ClimbLocators(std::string* error) {
  const size_t locators = pairs_of_group_[group_].size();
  const double spacing = 0.5 * gap_;
  const double depth = std::max(kClimbDepth * c_.foot_length, spacing);
  land_points_.clear(), land_locator_.clear(), land_first_.assign(1, 0);
  // Points a line: from `from` to `to` along the up, a point every sample spacing (at most
  // kMaxClimbPoints), the first one spacing from `from`.
  auto line = [&](const Vec3& from, double to, const Vec3& up) {
    const double span = to - Dot(from, up);
    const int count =
        std::clamp(static_cast<int>(std::ceil(std::fabs(span) / spacing)), 1, kMaxClimbPoints);
    for (int j = 1; j <= count; ++j) land_points_.push_back(from + up * (span * j / count));
    land_first_.push_back(land_points_.size());
  };
  for (size_t l = 0; l < points_.size(); ++l) {
    const Foothold& h = answers_[l];
    if (landed_[l] || h.status != Status::kOk) continue;
    const Agent& a = agents_[walking_[l / locators]];
    // A riser ahead: too steep to stand on, facing back along the heading more than across it
    // (a wall beside the body keeps its place, as QueryFootholds has it).
    if (Dot(h.normal, a.up) >= cos_max_slope_ ||
        -Dot(h.normal, a.forward) <= std::fabs(Dot(h.normal, Left(a))))
      continue;
    const double rest_height = Dot(points_[l], a.up) - 0.5 * lead_;
    const double snapped_height = Dot(h.point, a.up);
    const double top = rest_height + c_.max_rise + spacing;
    if (top <= snapped_height) continue;
    // Two lines: up inside the riser to max_rise above the rest height (its top), and down
    // before it to the rest height (the tread at its foot, when higher).
    land_locator_.push_back(l);
    line(h.point + a.forward * depth, top, a.up);
    line(h.point - a.forward * depth + a.up * spacing, rest_height - spacing, a.up);
  }
  if (land_points_.empty()) return Status::kOk;
  if (const Status s = SnapLandPoints(error); s != Status::kOk) return s;
  for (size_t i = 0; i < land_locator_.size(); ++i) {
    const size_t l = land_locator_[i];
    const Agent& a = agents_[walking_[l / locators]];
    const double snapped_height = Dot(answers_[l].point, a.up);
    const double rest_height = Dot(points_[l], a.up) - 0.5 * lead_;
    // The first ground straight over a point of the lines (within 1.5 spacings of it across
    // the up), facing the up: above the riser's snap on top of it, else before it, not above
    // the snap and above the rest height by more than a spacing (a tread up; a wall standing
    // on the feet's own ground stays where it snapped, for the step to be refused on it).
    for (size_t j = land_first_[2 * i]; j < land_first_[2 * i + 2]; ++j) {
      const Foothold& h = land_answers_[j];
      const bool on_top = j < land_first_[2 * i + 1];
      const double height = Dot(h.point, a.up);
      if (h.status != Status::kOk || Dot(h.normal, a.up) < cos_max_slope_ ||
          (on_top ? height <= snapped_height + 0.5 * spacing
                  : height > snapped_height + 0.5 * spacing || height <= rest_height + spacing) ||
          Length(ProjectOnPlane(h.point - land_points_[j], a.up)) > 0.75 * gap_)
        continue;
      answers_[l] = h, landed_[l] = 1;
      break;
    }
  }
  return Status::kOk;
}

Status Generator::QueryFootholds(std::string* error) {
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
          // looks over the void; one landed on the ground below its place (LandLocators) does
          // not. Round 0 holds every move, and answers_ the locator snaps.
          const size_t m = pending_[i];
          const size_t l = (m / per_agent) * locators + slot[m % per_agent];
          const Foothold& h = answers_[l];
          const Vec3& placed = points_[l];
          if (landed_[l] || Distance(h.point, placed) <= lead_) {
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
              // beside it. Multipeds' up is the ground's normal: they slide along it.) One that
              // climbed onto the next tread up beside the heading keeps its height but its place
              // across the heading (ClimbedAside).
              const Vec3 across = ProjectOnPlane(left, h.normal);
              const double lean = std::fabs(Dot(h.normal, left));
              const double off = Dot(h.point - placed, left);
              const double keep = Dot(across, left);  // 1 - lean^2
              if (keep > 0.25 && std::fabs(off) <= 0.5 * lead_ * lean + 0.5 * gap_)
                locator_[m] -= across * (off / keep);
              else if (ClimbedAside(h, placed, a, lean, off))
                locator_[m] -= left * off;
              else if (lean < kFlatLean && std::fabs(off) > gap_ &&
                       std::fabs(Dot(h.point - placed, a.up) + 0.5 * lead_) <= 0.5 * gap_)
                // Snapped aside across level ground, by more than two spacings, at the
                // height the place stands over: no ground under the place, beyond the edge
                // of the ground beside it. It keeps its place, as over a gap (kept on the
                // edge, it drew the feet of a biped heading at 25 to 60 degrees to a cliff's
                // edge along it, crabbing, their stance closing to a third).
                locator_[m] = placed - a.up * (0.5 * lead_), locator_normal_[m] = a.up;
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
        // outward, toward the foot's own side (KeepsSide says how far).
        if (mv.outward > 0) {
          const double side = rest_[mv.foot].x > rest_[mate_[mv.foot]].x ? 1.0 : -1.0;
          v += Left(a) * (side * mv.outward);
        }
        // (A step of under 2% of what this one may be, not of step_length: a slope_step_scale
        // below 0.02 made every step up a slope a step in place, and the walk a dead end.)
        if (Length(v) < kInPlace * std::min(c_.step_length, max_len)) {
          if (mv.attempt.drop > 0) {
            if (!StandAtEdge(mv)) Fail(mv);  // nothing ahead to aim down at
          } else {
            mv.done = true, mv.end = a.foot[mv.foot], mv.end_normal = a.foot_normal[mv.foot];
          }
          continue;
        }
        mv.step = v;  // aimed down, and held within reach, by FitInReach
      }
    });
    Parallel(walkers_.size(), [&](size_t wb, size_t we) {
      for (size_t i = wb; i < we; ++i)
        FitInReach(walkers_[i] * per_agent, (walkers_[i] + 1) * per_agent);
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
    // (With soles to fit, the reach is checked once they are: FitSoles queries in between.)
    const bool soles = c_.foot_length > 0;
    all_done_.assign(soles ? walkers_.size() : 0, 0);
    Parallel(walkers_.size(), [&](size_t wb, size_t we) {
      for (size_t i = wb; i < we; ++i) {
        const size_t m = walkers_[i] * per_agent, e = m + per_agent;
        bool all_done = true;
        for (size_t j = m; j < e; ++j) {
          if (moves[j].query != kNoQuery) {
            Judge(moves[j], next_answers_[moves[j].query]), moves[j].query = kNoQuery;
            if (!moves[j].done && moves[j].attempts >= kMaxAttempts && !StandAtEdge(moves[j]))
              KeepPlace(moves[j]);
          }
          all_done &= moves[j].done;
        }
        if (soles)
          all_done_[i] = all_done;
        else if (all_done)
          CheckReach(m, e);
      }
    });
    if (soles) {
      const Status fitted = FitSoles(error);
      if (fitted != Status::kOk) return fitted;
      Parallel(walkers_.size(), [&](size_t wb, size_t we) {
        for (size_t i = wb; i < we; ++i)
          if (all_done_[i]) CheckReach(walkers_[i] * per_agent, (walkers_[i] + 1) * per_agent);
      });
    }
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
  bool sideways = false;
  if (h.status == Status::kOk) {
    const Vec3 along = ProjectOnPlane(intended, h.normal);
    if (Length2(along) >= 0.25 * Length2(intended)) {
      const Vec3 moved = ProjectOnPlane(h.point - foot, h.normal);
      progress = Dot(moved, along) / Length2(along);
      // An upright character's, nor heading more than kMaxSidewaysDeg off the step: along a
      // cliff's edge at 45 degrees to the step, a foothold made just half the progress, and a
      // biped heading at that angle to the edge crabbed along it. (Multipeds turning on the
      // spot or along beams and blocks take footholds farther aside.)
      const Vec3 across = moved - along * progress;
      sideways = !c_.align_to_normal &&
                 Length(across) > std::tan(Radians(kMaxSidewaysDeg)) * progress * Length(along);
    }
  }
  const bool found = h.status == Status::kOk && progress >= 0.5 && !sideways;
  const double rise = found ? Dot(h.point - foot, a.up) : 0;
  const double rise_limit = c_.max_rise * (1 + kRiseRounding);
  if (found && std::fabs(rise) <= rise_limit && Dot(h.normal, a.up) >= cos_max_slope_) {
    if (KeepsSide(mv, h.point, h.normal)) mv.done = true;
    return;
  }
  if (mv.lined_up) {  // the outward retry was refused
    // Aimed farther than half a sample spacing (off the edge of a terrain the feet walk along),
    // it is asked again half a spacing outward; else the lined-up foothold it tried to better.
    if (NearerOutward(mv, kNearestOutward * gap_)) return;
    mv.done = true, mv.end = mv.lined_up_point, mv.end_normal = mv.lined_up_normal;
    return;
  }
  if (!KeepsReason(mv, !found)) return;  // mv already has a better reason
  Text why(3);                           // refused: say why (only built on this rare path)
  if (!found) {
    // Past the terrain's bounds by more than the radius, no sample can be a foothold.
    const double radius = kFootholdTolerance * c_.step_length;
    // (One aside of the step: past the bounds at all, where the nearest lies on their edge.)
    const bool aside = sideways && progress >= 0.5;
    const bool beyond = BoxDistance(mv.ideal, bounds_min_, bounds_max_) > (aside ? 0 : radius);
    why << "no foothold within " << radius << " of " << Point(mv.ideal);
    // The nearest lay aside of the step, along the edge of the ground beyond which it aims.
    if (aside) why << " ahead (the nearest, " << Point(h.point) << ", lies aside)";
    why << (beyond ? " (the terrain ends, or rises as a wall at its bounds, before it)"
                   : " (a gap or a cliff)");
    // Samples spread wider than half that radius leave gaps everywhere: say so, unless the
    // terrain simply ends there or resampling would not bring them closer.
    const double spacing = 0.5 * gap_;
    if (!beyond && !aside && spacing > 0.5 * kFootholdTolerance * c_.step_length &&
        kSeparationPerStep * c_.step_length < 0.8 * spacing) {
      why << "; the terrain's samples lie about " << spacing
          << " apart, too far for this character: resample it at a separation of "
          << kSeparationPerStep * c_.step_length
          << " (a mesh or height map: --separation; a point file is used as it is: sample its "
             "surface that finely)";
    }
  } else if (std::fabs(rise) > rise_limit) {
    why << "the foothold at " << Point(h.point) << (rise > 0 ? " rises " : " drops ")
        << Beyond(std::fabs(rise), c_.max_rise) << ", more than max_rise "
        << NumberText(c_.max_rise) << " (a cliff)";
  } else {
    const double slope = Degrees(AngleBetween(h.normal, a.up));
    why << "the foothold at " << Point(h.point) << " leans " << Beyond(slope, c_.max_slope_deg)
        << " deg, more than max_slope_deg " << NumberText(c_.max_slope_deg) << " (too steep)"
        << FacingDownHint(slope, c_.align_to_normal);
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
    if (std::fabs(gap - 1) < std::fabs(mv.lined_up_gap - 1)) {
      mv.end = p, mv.end_normal = normal, mv.outward_kept = true;
      return true;
    }
    if (NearerOutward(mv, kNearestOutward * gap_)) return false;
    mv.end = mv.lined_up_point, mv.end_normal = mv.lined_up_normal;
    return true;
  }
  mv.end = p, mv.end_normal = normal;
  // Lined up: under half the rest gap. The retry is aimed to three quarters of the rest gap
  // (the target itself was lined up: its locator caught on a stair's nose beside the heading,
  // as climbing stairs at 15 degrees to the treads, where a biped's downhill foot crossed the
  // other; or a sharp turn cut on the targets, not the footholds), and at least half a sample
  // spacing, at the sample on the foot's own side (on the bundled hills' 25 cm lattice a
  // biped's feet took one column of samples on a diagonal).
  if (gap >= kMinPairGap || mv.outward != 0) return true;
  const double rest_gap = std::fabs(rest_[mv.foot].x - rest_[mate_[mv.foot]].x);
  mv.outward = std::max(kNearestOutward * gap_, (kOutwardGoal - gap) * rest_gap);
  mv.lined_up = true, mv.lined_up_gap = gap;
  mv.lined_up_point = p, mv.lined_up_normal = normal;
  --mv.attempts;  // the same attempt again, aimed outward
  return false;
}

bool Generator::StandAtEdge(Move& mv) {
  if (!mv.at_edge) return false;
  mv.done = true, mv.at_edge = false, mv.sole = 1;
  mv.end = mv.edge_point, mv.end_normal = mv.edge_normal;
  return true;
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

void Generator::FitInReach(size_t m, size_t e) {
  const Agent& a = agents_[moves_[m].agent];
  const std::vector<int>& slot = move_of_foot_[group_];  // foot -> its move's offset, or -1
  const double feet = static_cast<double>(c_.feet.size());
  // A shorter retry shortens the step that fits (a step past reach, shortened first and then
  // fitted, aimed where the first try had, and was refused as often).
  auto shorter = [](const Move& mv) { return std::min(1.0, mv.attempt.scale); };
  // The feet's ground moves by every foot's displacement over the number of feet: the footholds
  // found so far, and the steps still to be asked, scaled by s.
  Vec3 found, asked;
  bool any = false;
  for (size_t i = m; i < e; ++i) {
    Move& mv = moves_[i];
    if (mv.failed) continue;
    if (mv.done) {
      found += mv.end - a.foot[mv.foot];
    } else {
      mv.step = mv.step / shorter(mv);
      asked += mv.step, any = true;
    }
  }
  if (!any) return;
  auto body = [&](double s) {
    return a.ground + (found + asked * s) / feet + a.body_up * c_.body_height;
  };
  // Planted feet count only where a hold would end the walk (every other group waited in a
  // row): elsewhere the group waits and the planted foot's own group steps on, as the gait has
  // it. Feet already beyond reach before the step do not count: no step brings them back.
  const bool planted = a.waits + 1 >= static_cast<int>(c_.gait.size());
  // Aimed half a sample spacing inside the reach, or half the room the foot has now if less:
  // the foothold is the sample nearest the aim, and one aimed right at the reach lay past it
  // as often as not (the shorter retries then took 0.6 of the step).
  const Vec3 now = body(0);
  auto within = [&](const Vec3& foot, const Vec3& step, const Vec3& b) {
    const double before = Distance(foot, now);
    const double margin = std::min(0.25 * gap_, 0.5 * (c_.reach - before));
    return before > c_.reach || Distance(foot + step, b) <= c_.reach - margin;
  };
  auto fits = [&](double s) {
    const Vec3 b = body(s);
    for (size_t i = m; i < e; ++i) {
      const Move& mv = moves_[i];
      if (!mv.failed && !mv.done && !within(a.foot[mv.foot], mv.step * s, b)) return false;
    }
    for (size_t f = 0; planted && f < c_.feet.size(); ++f)
      if (slot[f] < 0 && !within(a.foot[f], Vec3{}, b)) return false;
    return true;
  };
  // Up to 256 shortenings by a quarter (1e-32 of the step: the longest step_length a character
  // file may give, 1e9, against any reach down to 1e-23), then the longest that fits found
  // between the last two (a cut by a quarter alone kept a biped's steps near its reach a
  // quarter short for the whole walk).
  double s = 1;
  if (!fits(1)) {
    bool fitted = false;
    for (int shrink = 0; !(fitted = fits(s)) && shrink < 256; ++shrink) s *= 0.75;
    if (fitted) {
      double hi = s / 0.75;
      for (int it = 0; it < 24; ++it) {
        const double mid = 0.5 * (s + hi);
        (fits(mid) ? s : hi) = mid;
      }
    }
  }
  for (size_t i = m; i < e; ++i) {
    Move& mv = moves_[i];
    if (mv.failed || mv.done) continue;
    mv.step = mv.step * (s * shorter(mv)) -
              a.up * (mv.attempt.drop * c_.max_rise);  // the last retries aim down
    mv.ideal = a.foot[mv.foot] + mv.step;
  }
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
  const Vec3 up = GaitCycleUp(a.fitted_up, BodyUp(FeetUp(a.up, after, after_normals), after));
  const Vec3 body = centroid / static_cast<double>(feet) + up * c_.body_height;
  for (size_t i = m; i < e; ++i) {
    const double dist = Distance(moves[i].end, body);
    if (dist > c_.reach) {
      Text why(3);
      why << "the foothold at " << Point(moves[i].end) << " is " << Beyond(dist, c_.reach)
          << " from the body, beyond reach " << NumberText(c_.reach);
      // Room within reach narrower than the samples' spacing: no sample may lie within it (a
      // hexapod with 1 cm of room on a 2.5 cm grid stopped at its first step, saying only this).
      const double spacing = 0.5 * gap_;
      const double room =
          c_.reach - Distance(a.foot[moves[i].foot], a.ground + a.body_up * c_.body_height);
      if (room > 0 && room < spacing) {
        why << "; the foot had " << room << " of room within it, less than the terrain's "
            << "samples lie apart (about " << spacing << "): raise reach, or resample the terrain "
            << "finer";
      }
      moves[i].done = false;
      Reopen(moves[i]);
      if (KeepsReason(moves[i], false)) moves[i].reason = why.str(), moves[i].reason_is_gap = false;
    }
  }
  // A planted foot the body would leave beyond reach: every moving foot steps shorter.
  for (size_t f = 0; f < feet; ++f) {
    const double dist = Distance(a.foot[f], body);
    if (slot[f] >= 0 || dist <= c_.reach) continue;
    Text why(3);
    why << "the step would leave foot " << c_.feet[f].name << " " << Beyond(dist, c_.reach)
        << " from the body, beyond reach " << NumberText(c_.reach);
    for (size_t i = m; i < e; ++i) {
      if (!moves[i].done) continue;
      moves[i].done = false, moves[i].held_by_planted = true;
      Reopen(moves[i]);
      if (KeepsReason(moves[i], false)) moves[i].reason = why.str(), moves[i].reason_is_gap = false;
    }
    break;
  }
}

}  // namespace footfall::steps_detail
