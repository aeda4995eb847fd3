#include "walk_checks.h"

#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

#include "footfall/import/terrain_loader.h"

namespace footfall::test {

const std::vector<std::string>& ShippedCharacters() {
  static const std::vector<std::string> names = {"biped", "quadruped", "hexapod", "octopod"};
  return names;
}

Character LoadShipped(const std::string& name) {
  Character c;
  std::string error;
  const std::string path = std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/" + name + ".json";
  INFO(error);
  REQUIRE(LoadCharacter(path, &c, &error) == Status::kOk);
  return c;
}

RawSamples LoadShippedTerrain(const std::string& name) {
  RawSamples samples;
  std::string error;
  const std::string path = std::string(FOOTFALL_SOURCE_DIR) + "/data/terrain/" + name + ".pts";
  INFO(error);
  REQUIRE(footfall::LoadTerrain(path, TerrainLoadOptions{}, &samples, &error) == Status::kOk);
  return samples;
}

Terrain LoadTerrain(const RawSamples& samples, double spacing) {
  Terrain t;
  t.spacing = spacing;
  t.session = MakeEmbeddedSession();
  t.samples = samples;
  REQUIRE(t.session->LoadSamples(samples, "test", &t.handle) == Status::kOk);
  return t;
}

Walk Generate(Terrain& t, const Character& c, const GenerateOptions& o) {
  Walk w;
  std::string error;
  const Status s = GenerateWalk(*t.session, t.handle, c, o, &w, &error);
  INFO(error);
  REQUIRE(s == Status::kOk);
  return w;
}

Vec3 FootAt(const WalkTrack& track, double frame) {
  const auto& k = track.keys;
  if (frame <= k.front().frame) return k.front().position;
  for (size_t i = 1; i < k.size(); ++i) {
    if (frame <= k[i].frame) {
      const double t = (frame - k[i - 1].frame) / (k[i].frame - k[i - 1].frame);
      return Lerp(k[i - 1].position, k[i].position, t);
    }
  }
  return k.back().position;
}

std::vector<const WalkTrack*> TracksOf(const Walk& w, const std::string& character) {
  std::vector<const WalkTrack*> out;
  for (const WalkTrack& t : w.tracks)
    if (t.character == character) out.push_back(&t);
  return out;
}

namespace {

Vec3 QuatAxisY(const Quat& q) {
  return {2 * (q.x * q.y - q.w * q.z), 1 - 2 * (q.x * q.x + q.z * q.z),
          2 * (q.y * q.z + q.w * q.x)};
}

void CheckCharacter(Terrain& t, const Character& c, const GenerateOptions& o, const Walk& w,
                    const std::string& id) {
  INFO("character '" << id << "'");
  const auto tracks = TracksOf(w, id);
  REQUIRE(tracks.size() == c.feet.size() + 1);
  const WalkTrack& body = *tracks.back();
  REQUIRE(body.kind == TrackKind::kBody);
  REQUIRE(body.rotations.size() == body.keys.size());
  for (size_t f = 0; f < c.feet.size(); ++f) {
    REQUIRE(tracks[f]->name == c.feet[f].name);
    REQUIRE(tracks[f]->kind == TrackKind::kFoot);
    REQUIRE(tracks[f]->rotations.empty());
  }
  for (const WalkTrack* tr : tracks) {
    REQUIRE_FALSE(tr->keys.empty());
    for (size_t i = 1; i < tr->keys.size(); ++i) REQUIRE(tr->keys[i].frame > tr->keys[i - 1].frame);
  }
  // Every foot ends planted, by the body's last key: no step keyed for the feet alone (a step
  // the walk stopped at is taken back whole).
  for (size_t f = 0; f < c.feet.size(); ++f) {
    CHECK(tracks[f]->keys.back().phase == KeyPhase::kEnd);
    CHECK(tracks[f]->keys.back().frame <= body.keys.back().frame);
  }
  // Start and end keys on terrain samples, exactly.
  std::vector<Vec3> planted;
  std::vector<Vec3> normals;
  for (size_t f = 0; f < c.feet.size(); ++f)
    for (const WalkKey& k : tracks[f]->keys)
      if (k.phase != KeyPhase::kMid) planted.push_back(k.position), normals.push_back(k.normal);
  std::vector<Foothold> snapped(planted.size());
  REQUIRE(t.session->Snap(t.handle, planted.data(), planted.size(), snapped.data()) == Status::kOk);
  size_t off_terrain = 0;
  for (size_t i = 0; i < planted.size(); ++i)
    off_terrain += !(snapped[i].point == planted[i] && snapped[i].normal == normals[i]);
  CHECK(off_terrain == 0);
  // Planted feet stay put; arcs clear the terrain; phases in order.
  std::vector<Vec3> arc;
  std::vector<double> need;        // required clearance at each arc point
  std::vector<const WalkKey*> by;  // the foothold at that point's end of its arc
  for (size_t f = 0; f < c.feet.size(); ++f) {
    const auto& k = tracks[f]->keys;
    for (size_t i = 0; i + 1 < k.size(); ++i) {
      // After a touch-down the foot lifts from where it landed: a start key there, or, when it
      // lifts on the frame it landed (a gait of one group), its swing starts from the end key.
      if (k[i].phase == KeyPhase::kEnd) {
        REQUIRE(k[i + 1].phase != KeyPhase::kEnd);
        if (k[i + 1].phase == KeyPhase::kStart) REQUIRE(k[i + 1].position == k[i].position);
      }
      if (k[i].phase != KeyPhase::kStart && !SwingStartsAt(k, i)) continue;
      REQUIRE(i + 2 < k.size());
      REQUIRE(k[i + 1].phase == KeyPhase::kMid);
      REQUIRE(k[i + 2].phase == KeyPhase::kEnd);
      auto at = [&](double s) {
        return s <= 0.5 ? Lerp(k[i].position, k[i + 1].position, 2 * s)
                        : Lerp(k[i + 1].position, k[i + 2].position, 2 * s - 1);
      };
      for (int j = 1; j < 8; ++j) {
        const double s = j / 8.0;
        arc.push_back(at(s));
        need.push_back(0.25 * c.step_height * (1 - std::fabs(2 * s - 1)) - 1e-6);
        by.push_back(&k[s <= 0.5 ? i : i + 2]);
      }
      for (int j = 1; j < 10; ++j) {
        arc.push_back(at(j / 10.0)), need.push_back(-t.spacing - 1e-6), by.push_back(nullptr);
      }
    }
  }
  std::vector<Foothold> arc_snap(arc.size());
  REQUIRE(t.session->Snap(t.handle, arc.data(), arc.size(), arc_snap.data()) == Status::kOk);
  size_t below = 0;
  double worst = 0;
  for (size_t i = 0; i < arc.size(); ++i) {
    // Along the nearest sample's normal, or, when larger, the distance to it less twice the
    // spacing (no surface is nearer than that).
    const Vec3 v = arc[i] - arc_snap[i].point;
    double clearance = Dot(v, arc_snap[i].normal);
    if (clearance > 0 || Length2(v) - clearance * clearance > 4 * t.spacing * t.spacing)
      clearance = std::max(clearance, Length(v) - 2 * t.spacing);
    // A foothold standing against the sample's face (on ground facing more than 45 degrees
    // away, less than a step height in front of it: a toe at a riser): the arc near it keeps
    // at least half the foot's own distance from that face.
    double needed = need[i];
    if (by[i]) {
      const double kept = Dot(by[i]->position - arc_snap[i].point, arc_snap[i].normal);
      if (Dot(arc_snap[i].normal, by[i]->normal) < std::sqrt(0.5) && kept >= 0 &&
          kept <= c.step_height)
        needed = std::min(needed, 0.5 * kept - 1e-6);
    }
    if (clearance < needed) ++below, worst = std::min(worst, clearance - needed);
  }
  INFO("arc points not clear of the terrain: " << below << " of " << arc.size() << ", worst by "
                                               << worst);
  CHECK(below == 0);
  // The body follows the feet, clear of the terrain: body_height along its up above the feet's
  // centroid, or up to body_height more where the terrain comes nearer than half its
  // body_height (three times body_height more out of the terrain). It may lie behind its nearest
  // sample's plane only where rising would not help (that plane along its up: beside a wall's face
  // or over an edge) or may not (raised as far as the feet's reach or the raise's bound allow).
  const Vec3 world_up = Normalize(o.up);
  std::vector<Foothold> body_snap(body.keys.size());
  std::vector<Vec3> body_points;
  for (const WalkKey& b : body.keys) body_points.push_back(b.position);
  REQUIRE(t.session->Snap(t.handle, body_points.data(), body_points.size(), body_snap.data()) ==
          Status::kOk);
  for (size_t i = 0; i < body.keys.size(); ++i) {
    const WalkKey& b = body.keys[i];
    Vec3 centroid;
    double farthest = 0;
    for (size_t f = 0; f < c.feet.size(); ++f) {
      const Vec3 p = FootAt(*tracks[f], b.frame);
      centroid += p;
      farthest = std::max(farthest, Distance(p, b.position));
    }
    CHECK(farthest <= c.reach + 1e-9);
    centroid = centroid / static_cast<double>(c.feet.size());
    const Vec3 up = c.align_to_normal ? QuatAxisY(body.rotations[i]) : world_up;
    const double raised = Dot(b.position - centroid, up) - c.body_height;
    INFO("body key " << i << " at frame " << b.frame);
    CHECK(raised >= -1e-6);
    CHECK(raised <= 3 * c.body_height + 1e-6);
    CHECK(Distance(centroid + up * (c.body_height + raised), b.position) < 1e-6);
    const Vec3 v = b.position - body_snap[i].point;
    // (Behind a plane the most it may rise would not take it out of, a roof modelled as one
    // face over it, the body is not raised: the most is three times body_height, less where a
    // foot would be left beyond reach.)
    double most = 3 * c.body_height;
    for (size_t f = 0; f < c.feet.size(); ++f) {
      const Vec3 d = centroid + up * c.body_height - FootAt(*tracks[f], b.frame);
      const double h = Dot(d, up), disc = h * h - (Length2(d) - c.reach * c.reach);
      most = std::min(most, disc >= 0 ? -h + std::sqrt(disc) : 0.0);
    }
    const double height = Dot(v, body_snap[i].normal);
    const bool behind =
        height < -1e-9 && height + (most - raised) * Dot(up, body_snap[i].normal) >= -1e-9;
    const bool across = Dot(up, body_snap[i].normal) < 0.25;
    const bool bound = farthest >= c.reach - 1e-6 || raised >= 3 * c.body_height - 1e-6;
    CHECK((!behind || across || bound));
  }
  // Gait order: step k moves exactly group k % G, at frames start_frame + k * frames_per_step
  // (each computed so: a step's touch-down and the next one's lift-off are the same double).
  const size_t steps = body.keys.size() - 1;
  const int groups = static_cast<int>(c.gait.size());
  int waits = 0;
  size_t waits_from = 0;  // the body key the current run of waits starts at
  // A run of more than a cycle of waits is a character turning on the spot toward a waypoint,
  // its feet kept in place until the turn takes them on: its body turns during the run.
  const auto turned_since = [&](size_t from, size_t to) {
    const Quat a = body.rotations[from], b = body.rotations[to];
    return a.x != b.x || a.y != b.y || a.z != b.z || a.w != b.w;
  };
  for (size_t k = 0; k < steps; ++k) {
    const double f0 = o.start_frame + static_cast<double>(k) * c.frames_per_step;
    const double f1 = o.start_frame + static_cast<double>(k + 1) * c.frames_per_step;
    const auto& group = c.gait[k % groups];
    // A wait (its group held back by a foot left behind): no foot lifts and the body holds.
    bool any_lifts = false;
    for (size_t f = 0; f < c.feet.size(); ++f)
      for (size_t i = 0; i < tracks[f]->keys.size(); ++i)
        any_lifts |= SwingStartsAt(tracks[f]->keys, i) && tracks[f]->keys[i].frame == f0;
    if (!any_lifts) {
      INFO("step " << k + 1 << ": no foot lifts");
      CHECK(body.keys[k + 1].position == body.keys[k].position);
      CHECK(body.keys[k + 1].frame == f1);
      if (waits++ == 0) waits_from = k;
      if (waits >= groups) CHECK(!o.path.empty());  // a whole cycle of waits: a turn on the spot
      continue;
    }
    if (waits >= groups) {
      INFO("steps " << waits_from + 1 << " to " << k << ": no foot lifts");
      CHECK(turned_since(waits_from, k));
    }
    waits = 0;
    for (size_t f = 0; f < c.feet.size(); ++f) {
      bool lifts = false;
      for (size_t i = 0; i < tracks[f]->keys.size(); ++i)
        lifts |= SwingStartsAt(tracks[f]->keys, i) && tracks[f]->keys[i].frame == f0;
      const bool in_group =
          std::find(group.begin(), group.end(), static_cast<int>(f)) != group.end();
      INFO("step " << k + 1 << " foot " << c.feet[f].name);
      CHECK(lifts == in_group);
    }
    CHECK(body.keys[k + 1].frame == f1);
  }
}

}  // namespace

void CheckWalk(Terrain& t, const Character& c, const GenerateOptions& o, const Walk& w) {
  std::vector<std::string> ids;
  for (const WalkTrack& tr : w.tracks)
    if (tr.kind == TrackKind::kBody) ids.push_back(tr.character);
  // Every character has tracks but those left out of a crowd (their places snapped onto
  // another's start), each named in a stop.
  size_t left_out = 0;
  for (const std::string& stop : w.stops)
    left_out += stop.find("left out of the walk") != std::string::npos;
  REQUIRE(ids.size() + left_out == static_cast<size_t>(std::max(1, o.crowd)));
  for (const std::string& id : ids) CheckCharacter(t, c, o, w, id);
}

}  // namespace footfall::test
