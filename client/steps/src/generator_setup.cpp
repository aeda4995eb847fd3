// The step generator's setup (1-4): the start and its heading, each character of a crowd
// placed on its own ground, its feet snapped and planted, its body over them.
#include "step_generator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "footfall/terrain/shown_text.h"
#include "key_arena.h"

namespace footfall::steps_detail {

namespace {

// The world axis nearest `normal` as the up to give an upright character whose ground there
// faces across the world up it was given, written for where that up comes from (`up_name`):
// "Z up: --up 0,0,1" for the flag, "Z up: [0, 0, 1]" for a field of a scene file or of a
// generate request (JSON), where the flag form cannot be given.
std::string UpNearest(const Vec3& normal, const std::string& up_name) {
  const double c[3] = {normal.x, normal.y, normal.z};
  int axis = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(c[i]) > std::abs(c[axis])) axis = i;
  }
  const bool down = c[axis] < 0;
  const bool flag = up_name == GenerateInputNames().up;
  std::string value = flag ? "" : "[";
  for (int i = 0; i < 3; ++i) {
    if (i > 0) value += flag ? "," : ", ";
    value += i != axis ? "0" : down ? "-1" : "1";
  }
  value += flag ? "" : "]";
  return std::string(down ? "-" : "") + "XYZ"[axis] + " up: " + (flag ? "--up " : "") + value;
}

}  // namespace

Status Generator::Setup(std::string* error) {
  const size_t feet = c_.feet.size();
  TerrainInfo info;
  Status s = Check(session_.Info(terrain_, &info), "terrain info", error);
  if (s != Status::kOk) return s;
  const GridStats& g = info.stats;
  bounds_min_ = g.bounds_min, bounds_max_ = g.bounds_max;
  gap_ = 2 * g.spacing;
  // 1. The start: --start, or the centre of the top of the bounds; either may move to where
  //    the character can stand.
  const Vec3 start =
      o_.has_start ? o_.start : TopCentre(info.stats.bounds_min, info.stats.bounds_max, world_up_);
  Foothold first;
  s = FindStart(start, !o_.has_start || o_.start_may_move, &first, error);
  if (s != Status::kOk) return s;
  // A start given off the terrain by more than a step across the up (past its edge, or high
  // above a slope it slid down) is not where the character walks: say where it stands instead.
  // Along the up it is the ground below (a start at y = 0 over hills), as expected; the up is
  // --up for upright characters and, for those whose up follows the terrain, the normal of
  // the sample it snapped to (a start beside a wall stands on it). (The default start is the
  // top of the bounds: its snap is no news.)
  setup_notes_.clear();
  start_beyond_reach_.clear();
  start_beyond_reach_agent_ = std::numeric_limits<size_t>::max();
  if (o_.has_start) {
    const Vec3 up = c_.align_to_normal && !start_along_up_ ? start_snap_.normal : world_up_;
    const double across = Length(ProjectOnPlane(start - start_snap_.point, up));
    if (across > c_.step_length) {
      Text m(4);
      m << "the start " << Point(start) << " (" << o_.names.start
        << ") snaps to the terrain's sample nearest it, " << Point(start_snap_.point) << ", "
        << across << " away across the up (more than a step, " << c_.step_length
        << "): the character starts "
        << (first.point == start_snap_.point ? std::string("there") : "at " + Point(first.point));
      setup_notes_.push_back(m.str());
    }
  }
  // A step_length longer than the reach lets a foot travel is shortened at every step (7):
  // said once, with the step the character actually takes on level ground.
  const double longest = LongestStepInReach();
  if (c_.step_length > kReachNoteMargin * longest) {
    Text m(3);
    m << "step_length " << c_.step_length << " is longer than reach " << c_.reach
      << " lets a foot travel (about " << longest
      << " on level ground, for the foot with the least room): every step is shortened to keep "
         "the feet within reach of the body (raise reach or lower step_length)";
    setup_notes_.push_back(m.str());
  }
  AddCharacterShapeNotes();
  AddUnitsNote(g);
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
  // How far each place snapped sideways: onto ground facing the grid's up, across that ground
  // (off its normal): a place off the terrain's edge snaps across it, one above or
  // below it (a grid over hills) along its normal, give or take the samples' spacing. Onto a
  // wall (a place over a drop beside a block) the whole way.
  std::vector<double> snapped_across(n);
  for (int i = 0; i < n; ++i) {
    const Foothold& h = answers_[i];
    snapped_start[i] = h.point;
    const Vec3 moved = points_[i] - h.point;
    snapped_across[i] = Dot(h.normal, grid_up) >= std::cos(Radians(kFloorUpDeg))
                            ? Length(ProjectOnPlane(moved, h.normal))
                            : Length(moved);
  }
  // Why places snap together: a grid finer than the terrain's samples (its neighbours snap onto
  // one sample anywhere), samples coarse for the spacing, or a place off the terrain or over a
  // drop (it snaps onto the edge another snaps onto). (Every case but the first was said as
  // "the grid runs off the terrain there", for places well inside it too.)
  const double sample_gap = 0.5 * gap_;
  // (Measured from the place to the ground it snapped to, places 0.1 above coarse samples on
  // hills, 1.35 m inside the terrain, were said to be off its edge.)
  auto crowded_why = [&](int i) {
    Text why(3);
    if (bounds_min_ == bounds_max_) {  // one sample, or all at one point: no spacing to blame
      why << "the terrain is a single point, onto which every place snaps";
    } else if (spacing < sample_gap) {
      why << "the crowd's spacing, " << spacing << ", is finer than the terrain's samples, "
          << "about " << sample_gap << " apart";
    } else if (snapped_across[i] > 0.25 * spacing + sample_gap) {
      why << "its place snaps " << snapped_across[i] << " sideways: the grid "
          << "runs off the terrain, or over a drop, there";
    } else {
      why << "the terrain's samples, about " << sample_gap << " apart, are coarse for the "
          << "crowd's spacing, " << spacing << ": give a wider " << o_.names.crowd_spacing;
    }
    return why.str();
  };
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
  // heading on a Z-up terrain would walk a multiped downhill. Judged at the start given (a
  // crowd's), not at any one member's place: a member whose up differs there (on a block's
  // side) takes the heading turned onto its ground (Orient), and stops on its own if it
  // cannot walk.
  if (o_.path.empty() && n > 0) {
    constexpr double kMinDegreesFromUp = 10;
    const double min_sin = std::sin(Radians(kMinDegreesFromUp));
    const Vec3& up = up0;
    if (Length2(ProjectOnPlane(o_.heading, up)) <= min_sin * min_sin * Length2(o_.heading)) {
      Text m;
      m << "the heading " << Point(o_.heading) << " is along the up " << Point(up)
        << " where the character starts (within " << kMinDegreesFromUp
        << " deg of it): it gives no clear direction on the ground; give a heading along the "
           "ground ("
        << o_.names.heading << ")";
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
      if (!body)
        t.foot_length = c_.foot_length, t.foot_width = c_.foot_length > 0 ? c_.foot_width : 0;
      walk_.tracks.push_back(std::move(t));
    }
  }
  // 3. Snap the feet at their rest positions around each start (soles fitted: FitStartSoles).
  points_.resize(n * feet);
  for (int i = 0; i < n; ++i)
    for (size_t f = 0; f < feet; ++f) points_[i * feet + f] = Place(agents_[i], rest_[f]);
  answers_.resize(points_.size());
  s = Check(session_.Snap(terrain_, points_.data(), points_.size(), answers_.data()), "snap feet",
            error);
  if (s == Status::kOk)
    s = SnapFeetFacingUp(points_.data(), answers_.data(), points_.size(), feet, agents_.data(),
                         error);
  if (s == Status::kOk)
    s = SeparateSharedFeet(points_.data(), answers_.data(), points_.size(), feet, error);
  if (s == Status::kOk)
    s = FitStartSoles(answers_.data(), answers_.size(), feet, agents_.data(), error);
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
      Text m(3);
      m << "step 1 of " << a.id << ": its place on the crowd's grid, "
        << Point(first.point + offsets[i]) << ", snaps to " << Point(snapped_start[i]) << ", only "
        << Distance(snapped_start[i], snapped_start[crowded[i]]) << " from " << other.id
        << "'s start (" << crowded_why(i) << "): left out of the walk";
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
    Text m;
    m << "step 1 of " << a.id << ": its feet, around " << Point(a.ground) << ", stand where "
      << agents_[stacked[i]].id << "'s do (" << crowded_why(i) << "): left out of the walk";
    a.walking = false, a.left_out = true;
    a.stopped = m.str(), a.stopped_step = 1;
  }
  // A foot planted on the sample another character's foot stands on, where their starts were
  // pushed together (onto the terrain's edge: a quarter nearer than their places on the grid,
  // beyond what the samples' spacing explains): the one pushed farther is left out (a foot
  // each on one sample, at the edge of rocks). Neighbours on coarse samples keep sharing one.
  std::unordered_map<uint32_t, int> foot_owner;  // sample index -> the character standing on it
  std::vector<int> by_push(static_cast<size_t>(n));
  std::vector<double> push(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) by_push[i] = i, push[i] = Distance(places[i], snapped_start[i]);
  std::stable_sort(by_push.begin(), by_push.end(), [&](int a, int b) { return push[a] < push[b]; });
  for (int i : by_push) {
    Agent& a = agents_[i];
    if (a.left_out) continue;
    const Foothold* planted = &answers_[static_cast<size_t>(i) * feet];
    int other = -1;
    size_t foot = 0;
    // (A character stopped at its start keeps its keys, and its feet their samples.)
    for (size_t f = 0; f < feet && other < 0 && a.walking; ++f) {
      if (planted[f].status != Status::kOk) continue;
      const auto it = foot_owner.find(planted[f].index);
      if (it == foot_owner.end()) continue;
      const int j = it->second;
      if (Distance(snapped_start[i], snapped_start[j]) <
          0.75 * Distance(places[i], places[j]) - gap_)
        other = j, foot = f;
    }
    if (other < 0) {
      for (size_t f = 0; f < feet; ++f)
        if (planted[f].status == Status::kOk) foot_owner.emplace(planted[f].index, i);
      continue;
    }
    Text m;
    m << "step 1 of " << a.id << ": its foot " << c_.feet[foot].name << ", at "
      << Point(planted[foot].point) << ", stands on the sample a foot of " << agents_[other].id
      << " does (" << crowded_why(i) << "): left out of the walk";
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
      // In unsigned arithmetic: cells far from the origin overflowed the signed products.
      const auto u = [](int64_t v) { return static_cast<uint64_t>(v); };
      return static_cast<size_t>(u(c[0]) * 73856093u ^ u(c[1]) * 19349663u ^ u(c[2]) * 83492791u);
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

Status Generator::SnapFeetFacingUp(const Vec3* places, Foothold* feet, size_t total, size_t count,
                                   const Agent* agents, std::string* error) {
  if (count == 0) return Status::kOk;
  // The way a foot snaps again, and the least dot of the ground it takes with its up: lifted
  // along the up from a face turned away (ground facing the up), or out from a face too steep
  // to stand on (a riser its rest lies against: ground within max_slope_deg of the up; for a
  // multiped, the start's normal).
  std::vector<size_t> turned;
  std::vector<Vec3> way;
  std::vector<double> lift, least;
  for (size_t f = 0; f < total; ++f) {
    if (feet[f].status != Status::kOk) continue;
    const Vec3& up = agents[f / count].up;
    const double along = Dot(feet[f].normal, up);
    Vec3 out;
    double need = 0;
    if (along < 0) {
      out = up;
    } else if (along < cos_max_slope_) {
      out = NormalizeOr(ProjectOnPlane(feet[f].normal, up), Vec3{});
      need = cos_max_slope_;
    }
    if (Length2(out) == 0) continue;
    turned.push_back(f), way.push_back(out), least.push_back(need);
    lift.push_back(std::max(2 * Distance(places[f], feet[f].point), gap_ / 2));
  }
  std::vector<Vec3> lifted;
  std::vector<Foothold> again;
  while (!turned.empty()) {
    lifted.clear();
    for (size_t i = 0; i < turned.size(); ++i)
      lifted.push_back(places[turned[i]] + way[i] * lift[i]);
    again.assign(lifted.size(), Foothold{});
    const Status s = Check(session_.Snap(terrain_, lifted.data(), lifted.size(), again.data()),
                           "snap feet", error);
    if (s != Status::kOk) return s;
    size_t kept = 0;
    for (size_t i = 0; i < turned.size(); ++i) {
      const size_t f = turned[i];
      const double along = Dot(again[i].normal, agents[f / count].up);
      if (again[i].status == Status::kOk && along > 0 && along >= least[i] &&
          Distance(places[f], again[i].point) <= c_.reach) {
        feet[f] = again[i];
        continue;
      }
      // None within reach (or no lift to double): as it snapped.
      if (!(lift[i] > 0) || 2 * lift[i] > c_.reach) continue;
      turned[kept] = f, way[kept] = way[i], least[kept] = least[i], lift[kept] = 2 * lift[i];
      ++kept;
    }
    turned.resize(kept), way.resize(kept), least.resize(kept), lift.resize(kept);
  }
  return Status::kOk;
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
        Distance(places[f], h.point) > Distance(places[f], feet[f].point) + gap_ ||
        (!c_.align_to_normal && Dot(h.normal, world_up_) < cos_max_slope_))
      continue;
    bool taken = false;
    for (size_t g = c; g < c + count; ++g) taken |= g != f && feet[g].index == h.index;
    if (!taken) feet[f] = h;
  }
  return Status::kOk;
}

bool Generator::GroundAlongUp(const Vec3& start, Foothold* first, std::string* error,
                              Status* status) {
  return SettleAlongUp(
      start, world_up_, c_.step_length, first,
      [&](const Vec3& q, Foothold* next) {
        *status = Check(session_.Snap(terrain_, &q, 1, next), "snap start", error);
        return *status == Status::kOk && next->status == Status::kOk;
      },
      [](const Foothold& f) { return f.point; });
}

Status Generator::FindStart(const Vec3& start, bool may_move, Foothold* first, std::string* error) {
  Status s = Check(session_.Snap(terrain_, &start, 1, first), "snap start", error);
  if (s != Status::kOk) return s;
  start_along_up_ =
      o_.has_start && first->status == Status::kOk && GroundAlongUp(start, first, error, &s);
  if (s != Status::kOk) return s;
  start_snap_ = *first;
  if (first->status != Status::kOk) {
    *error =
        first->status == Status::kInvalidArgument
            ? (o_.names.start == "--start" ? std::string("the start (--start)") : o_.names.start) +
                  " is too far from the terrain to snap (queries reach 1e15 from it)"
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

double Generator::LongestStepInReach() const {
  // Walking straight, each foot lands d = L (G - 1) / (2G) ahead of its rest relative to the
  // body and lifts d behind it. 7 checks a step toward that landing against where its group's
  // steps take the body (g/n of it, for g feet of n in the group): the foot ends
  // r.z - d + L (1 - g/n) ahead, r.z + k L, within reach of a body body_height above the
  // feet's ground.
  const double groups = static_cast<double>(c_.gait.size());
  const double feet = static_cast<double>(c_.feet.size());
  double longest = std::numeric_limits<double>::infinity();
  for (const std::vector<int>& group : c_.gait) {
    const double k = (1 - static_cast<double>(group.size()) / feet) - (groups - 1) / (2 * groups);
    if (!(k > 0)) continue;  // the body moves with the foot: no step takes it out of reach
    for (int f : group) {
      const Vec3& r = rest_[f];
      const double up = c_.body_height - r.y;
      const double along2 = c_.reach * c_.reach - r.x * r.x - up * up;
      longest = std::min(longest, along2 > 0 ? (std::sqrt(along2) - r.z) / k : 0.0);
    }
  }
  return std::max(longest, 0.0);
}

void Generator::AddCharacterShapeNotes() {
  // A step_height that lifts a foot's mid key out of reach of the body (on level ground, the
  // foot halfway through its swing about its rest, step_height above the ground) is said too:
  // the mid keys are keyed there all the same.
  const double mid = MidKeyDistance();
  if (mid > c_.reach * (1 + 1e-9)) {
    Text m(3);
    m << "step_height " << c_.step_height << " lifts the feet's mid keys about " << mid
      << " from the body on level ground, beyond reach " << c_.reach
      << " (they are keyed there all the same: lower step_height or raise reach)";
    setup_notes_.push_back(m.str());
  }
  // Rests far off the ground plane (y, along the up, large beside x and z): most likely written
  // the Z-up way, [x, forward, 0], which puts the forward offsets along the up and collapses the
  // stance. Said once, for the foot farthest off.
  double off = 0, across = 0;
  size_t off_foot = 0;
  for (size_t f = 0; f < c_.feet.size(); ++f) {
    const Vec3& r = c_.feet[f].rest;
    across = std::max(across, std::hypot(r.x, r.z));
    if (std::fabs(r.y) > off) off = std::fabs(r.y), off_foot = f;
  }
  if (off > kOffGroundRestShare * across) {
    Text m(3);
    m << "foot " << c_.feet[off_foot].name << " rests " << c_.feet[off_foot].rest.y
      << " along the up (rest y), against at most " << across
      << " across it: rests are [side, up, forward], y along the up (as in Maya); a rig written "
         "Z-up as [x, forward, 0] puts its forward offsets along the up";
    setup_notes_.push_back(m.str());
  }
  // Feet resting nearly where another does, under a tenth of the reach (rests equal are refused
  // with the character file), take the same footholds: said once, for the nearest two.
  double nearest = std::numeric_limits<double>::infinity();
  size_t near_a = 0, near_b = 0;
  for (size_t a = 0; a < c_.feet.size(); ++a)
    for (size_t b = a + 1; b < c_.feet.size(); ++b)
      if (const double d = Distance(c_.feet[a].rest, c_.feet[b].rest); d < nearest)
        nearest = d, near_a = a, near_b = b;
  if (nearest < kNearRestsShare * c_.reach) {
    Text m(3);
    m << "feet " << c_.feet[near_a].name << " and " << c_.feet[near_b].name << " rest only "
      << nearest << " apart, under a tenth of reach " << c_.reach
      << ": they may plant on the same samples and walk in single file (spread their rest "
         "positions)";
    setup_notes_.push_back(m.str());
  }
}

void Generator::AddUnitsNote(const GridStats& g) {
  const Vec3 size = g.bounds_max - g.bounds_min;
  const double across = std::max({size.x, size.y, size.z});
  Text m(3);
  if (g.spacing > kUnitsNoteSpacingSteps * c_.step_length) {
    m << "the terrain's samples lie about " << g.spacing << " apart, more than "
      << kUnitsNoteSpacingSteps << " of this character's steps (step_length " << c_.step_length
      << "): if the terrain is in smaller units than the character (centimetres against "
         "metres), scale the character to it ("
      << o_.names.scale << "; 100 from metres to centimetres)";
  } else if (across > 0 && across < c_.reach) {
    m << "the terrain is " << across << " across, less than this character's reach " << c_.reach
      << ": if the character is in smaller units than the terrain (centimetres against "
         "metres), scale it to the terrain ("
      << o_.names.scale << "; 0.01 from centimetres to metres)";
  } else {
    return;
  }
  setup_notes_.push_back(m.str());
}

double Generator::MidKeyDistance() const {
  // Halfway through its swing a foot is about at its rest relative to the body (it lifts as
  // far behind as it lands ahead), raised step_height off the ground the body stands
  // body_height above.
  double farthest = 0;
  for (const Vec3& r : rest_) {
    const double up = c_.body_height - r.y - c_.step_height;
    farthest = std::max(farthest, std::sqrt(r.x * r.x + up * up + r.z * r.z));
  }
  return farthest;
}

void Generator::Orient(Agent& a, const Foothold& ground, const Vec3& up0, const Vec3& fwd0) const {
  a.ground = ground.point;
  a.up = c_.align_to_normal ? ground.normal : world_up_;
  a.forward = TangentForward(o_.heading, fwd0, up0, a.up);
  // Facing the first waypoint beyond its radius along the ground: one at the start (a path
  // drawn from where the character stands) counts as reached on the first step, so it gives no
  // direction. (Before the waypoints' distances from the terrain are known: taken as off it.)
  for (size_t i = 0; i < a.path.size(); ++i) {
    const Vec3 to = OnGround(a, ToPathPoint(a, a.path[i], false), false);
    if (Length(to) > Radius(a, i)) {
      a.forward = Normalize(to);
      return;
    }
  }
  // Every waypoint within its radius: toward the first that is off the start at all.
  for (const Vec3& p : a.path) {
    const Vec3 to = OnGround(a, ToPathPoint(a, p, false), false);
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
  a.body_up = a.fitted_up = BodyUp(a.up, a.foot);
  a.forward = TangentForward(a.forward, a.forward, old_up, a.up);
  a.ground = centroid / static_cast<double>(n);
  for (size_t f = 0; f < n; ++f) {
    const double slope = Degrees(AngleBetween(a.foot_normal[f], a.up));
    if (slope > c_.max_slope_deg) {
      Text m(3);
      m << "foot " << c_.feet[f].name << " cannot stand at " << Point(a.foot[f])
        << ": ground leans " << Beyond(slope, c_.max_slope_deg) << " deg, more than max_slope_deg "
        << NumberText(c_.max_slope_deg) << FacingDownHint(slope, c_.align_to_normal);
      // An upright character starting on ground across its up: a terrain whose up is another
      // axis (a height map read with --up-axis z) with the default world up.
      if (!c_.align_to_normal && slope > 60 && slope < 120)
        m << "; if the terrain's up is not " << Point(world_up_) << ", give the world up with "
          << o_.names.up << " (" << UpNearest(a.foot_normal[f], o_.names.up) << ")";
      return m.str();
    }
  }
  return "";
}

}  // namespace footfall::steps_detail
