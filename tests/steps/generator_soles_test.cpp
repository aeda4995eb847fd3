// Soles: a character with a foot_length sets each foot's sole on the tread it stands on.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "footfall/import/terrain_generators.h"
#include "footfall/steps/walk_json.h"
#include "generator_fixtures.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

namespace {

struct SoleCount {
  int fit = 0, touchdowns = 0;
};

// Counts the touch-downs of w (its end keys that moved the foot) whose sole, `length` long along
// the unit horizontal `heading` with its foothold at the middle, lies over the foothold's own
// tread within `slack` of that tread's ends, on a flight along +z (tread k at height k * rise,
// from z = k * run to (k + 1) * run; `treads` of them).
SoleCount SolesOnTreads(const Walk& w, const Vec3& heading, double length, double rise, double run,
                        int treads, double slack) {
  SoleCount n;
  for (const WalkTrack& t : w.tracks) {
    if (t.kind != TrackKind::kFoot) continue;
    for (size_t i = 0; i + 2 < t.keys.size(); ++i) {
      if (t.keys[i].phase != KeyPhase::kStart) continue;
      const Vec3& p = t.keys[i + 2].position;
      if (Distance(p, t.keys[i].position) == 0) continue;  // a step in place
      const int k = static_cast<int>(std::lround(p.y / rise));
      const double lo = k * run - slack, hi = (k + 1) * run + slack;
      const double heel = p.z - 0.5 * length * heading.z, toe = p.z + 0.5 * length * heading.z;
      ++n.touchdowns;
      // (The top tread has no riser beyond it: its far end is the terrain's.)
      n.fit += std::min(heel, toe) >= lo && (std::max(heel, toe) <= hi || k == treads - 1);
    }
  }
  return n;
}

// Whether the sole of each foot where w starts (its first key) lies over that foot's tread,
// as SolesOnTreads counts a touch-down: the number that do, of `feet`.
int StartSolesOnTreads(const Walk& w, const Vec3& heading, double length, double rise, double run,
                       int treads, double slack, int* feet) {
  int fit = 0;
  *feet = 0;
  for (const WalkTrack& t : w.tracks) {
    if (t.kind != TrackKind::kFoot || t.keys.empty()) continue;
    const Vec3& p = t.keys.front().position;
    const int k = static_cast<int>(std::lround(p.y / rise));
    const double lo = k * run - slack, hi = (k + 1) * run + slack;
    const double heel = p.z - 0.5 * length * heading.z, toe = p.z + 0.5 * length * heading.z;
    ++*feet;
    fit += (std::min(heel, toe) >= lo || k == 0) && (std::max(heel, toe) <= hi || k == treads - 1);
  }
  return fit;
}

}  // namespace

TEST_CASE("A biped with a foot length starts with its soles on the treads, and off the risers",
          "[steps][generator][soles]") {
  // The feet stood where their rests snapped: a start near a nose hung a heel or a toe over
  // the drop, and a start near a riser's foot snapped a foot onto the riser, where the walk
  // stopped at once (a foot cannot stand on ground leaning 90 degrees: at 20 degrees to the
  // treads, every start in the last tenth of the tread).
  const Character shipped = LoadShipped("biped");
  Character point = shipped;
  point.foot_length = 0;
  const int treads = 12;
  const double rise = 0.18, run = 0.3, spacing = 0.03;
  Terrain t = LoadTerrain(MakeStairs(treads, rise, run, 6, spacing), spacing);
  int fit = 0, feet = 0, point_fit = 0;
  for (const double deg : {0.0, 20.0, 180.0}) {
    const double a = deg * 3.14159265358979 / 180;
    const Vec3 heading{std::sin(a), 0, std::cos(a)};
    for (int i = 0; i < 10; ++i) {
      const int k = 5;
      GenerateOptions o = StartOptions({3, k * rise + 0.02, (k + (i + 0.5) / 10) * run}, 2);
      o.heading = heading;
      const Walk w = Generate(t, shipped, o);
      INFO(deg << " deg, start " << i << ": " << w.stopped);
      CheckWalk(t, shipped, o, w);
      CHECK(w.stopped.empty());
      int n = 0;
      fit += StartSolesOnTreads(w, heading, shipped.foot_length, rise, run, treads, spacing, &n);
      feet += n;
      const Walk v = Generate(t, point, o);
      point_fit +=
          StartSolesOnTreads(v, heading, shipped.foot_length, rise, run, treads, spacing, &n);
    }
  }
  INFO(fit << " of " << feet << " start soles on their treads, point feet " << point_fit);
  CHECK(feet == 60);
  CHECK(fit >= feet - 2);
  CHECK(point_fit < feet - 15);
  // A stance straddling a riser on coarse samples: one rest lies under the tread above, and
  // the foot off the riser took its mate's sample; moved off it again from the far side of its
  // rest, it went back onto the riser, and the walk stopped at once. The two feet now share
  // the sample and walk.
  Terrain coarse = LoadTerrain(MakeStairs(12, 0.35, 0.25, 10, 0.08), 0.08);
  GenerateOptions o = StartOptions({9, 2.1, 1.625}, 8);
  o.heading = {-0.96268, 0, -0.270643};
  const Walk w = Generate(coarse, shipped, o);
  INFO(w.stopped);
  CheckWalk(coarse, shipped, o, w);
  CHECK(w.stopped.empty());
  for (const WalkTrack& t : w.tracks) CHECK(t.keys.front().normal.y > 0.99);
}

TEST_CASE("A biped with a foot length sets its soles on the treads, up and down stairs",
          "[steps][generator][soles]") {
  // A foothold is the sample nearest the step's aim: on stairs the biped stood its feet on the
  // nose going down (the sole's front half over the drop, 16 of 17 touch-downs on 18 x 30 cm
  // stairs) and at the riser's foot going up (its toe in the riser, 7 of 13). With a
  // foot_length, each foothold moves along its tread until heel and toe have ground.
  const Character shipped = LoadShipped("biped");
  REQUIRE(shipped.foot_length > 0);
  Character point = shipped;
  point.foot_length = 0;
  struct Flight {
    double rise, run, spacing, deg;
  };
  const int treads = 20;
  SoleCount with, without;
  for (const Flight& f :
       {Flight{0.18, 0.3, 0.03, 0}, Flight{0.15, 0.35, 0.05, 0}, Flight{0.2, 0.28, 0.02, 0},
        Flight{0.12, 0.4, 0.04, 20}, Flight{0.17, 0.32, 0.04, 30}}) {
    Terrain t = LoadTerrain(MakeStairs(treads, f.rise, f.run, 6, f.spacing), f.spacing);
    for (const bool up : {true, false}) {
      const int from = up ? 1 : treads - 2;
      GenerateOptions o = StartOptions({3, from * f.rise, (from + 0.5) * f.run}, 10);
      const double a = f.deg * 3.14159265358979 / 180;
      const Vec3 heading{std::sin(a), 0, (up ? 1 : -1) * std::cos(a)};
      o.heading = heading;
      const Walk w = Generate(t, shipped, o);
      INFO(f.rise << " x " << f.run << " every " << f.spacing << " at " << f.deg << " deg, "
                  << (up ? "up: " : "down: ") << w.stopped);
      CheckWalk(t, shipped, o, w);
      CHECK(w.stopped.empty());
      const SoleCount n =
          SolesOnTreads(w, heading, shipped.foot_length, f.rise, f.run, treads, f.spacing);
      CHECK(n.touchdowns >= 8);
      CHECK(n.fit >= n.touchdowns - 1);
      with.fit += n.fit, with.touchdowns += n.touchdowns;
      const Walk v = Generate(t, point, o);
      const SoleCount m =
          SolesOnTreads(v, heading, shipped.foot_length, f.rise, f.run, treads, f.spacing);
      without.fit += m.fit, without.touchdowns += m.touchdowns;
    }
  }
  INFO(with.fit << " of " << with.touchdowns << " soles on their treads, point feet " << without.fit
                << " of " << without.touchdowns);
  CHECK(with.fit > without.fit + with.touchdowns / 4);
}

TEST_CASE("A biped with a foot length steps down steep stairs a tread at a time",
          "[steps][generator][soles]") {
  // Down risers as tall as the treads are deep, its short steps found the nose of the tread it
  // stood on: moved back from that edge, the foot found the same edge at its next step and
  // shuffled to it, two steps a tread. A foot stepping to the edge of its own tread now steps
  // down past it first.
  const Character c = LoadShipped("biped");
  const int treads = 16;
  for (const double deg : {0.0, 15.0}) {
    const double rise = 0.3, run = 0.3, spacing = 0.04;
    Terrain t = LoadTerrain(MakeStairs(treads, rise, run, 6, spacing), spacing);
    const int from = treads - 2;
    GenerateOptions o = StartOptions({3, from * rise, (from + 0.5) * run}, 12);
    const double a = deg * 3.14159265358979 / 180;
    o.heading = {std::sin(a), 0, -std::cos(a)};
    const Walk w = Generate(t, c, o);
    INFO(deg << " deg: " << w.stopped);
    CheckWalk(t, c, o, w);
    CHECK(w.stopped.empty());
    const auto& body = Body(w).keys;
    CHECK(body.front().position.y - body.back().position.y >= 5 * rise - 1e-6);
    const SoleCount n = SolesOnTreads(w, o.heading, c.foot_length, rise, run, treads, spacing);
    CHECK(n.fit >= n.touchdowns - 2);
  }
}

TEST_CASE("A biped's soles change nothing on ground that has room for them",
          "[steps][generator][soles]") {
  // On flat ground and the bundled hills every sole has ground under heel and toe: the walk is
  // the point-footed one.
  const Character shipped = LoadShipped("biped");
  Character point = shipped;
  point.foot_length = 0;
  Terrain flat = LoadTerrain(MakeFlat(201, 0.05, 0), 0.05);
  Terrain hills = LoadTerrain(LoadShippedTerrain("hills"), 0.25);
  for (Terrain* t : {&flat, &hills}) {
    GenerateOptions o = StartOptions(t == &flat ? Vec3{3, 0, 1} : Vec3{12, 0, 8}, 12);
    o.heading = {0.3, 0, 1};
    const Walk w = Generate(*t, shipped, o), v = Generate(*t, point, o);
    CheckWalk(*t, shipped, o, w);
    REQUIRE(w.tracks.size() == v.tracks.size());
    for (size_t i = 0; i < w.tracks.size(); ++i) {
      REQUIRE(w.tracks[i].keys.size() == v.tracks[i].keys.size());
      for (size_t j = 0; j < w.tracks[i].keys.size(); ++j)
        CHECK(w.tracks[i].keys[j].position == v.tracks[i].keys[j].position);
    }
  }
}

TEST_CASE("A biped with a foot width keeps its soles off a side edge",
          "[steps][generator][soles]") {
  // Ground ending at x = 2 beside a biped walking along +z, its left foot 1 cm inside the edge:
  // without a width the sole hung half over the drop. With one, every foot (at the start and
  // at each touch-down) stands where both sides of its sole have ground of their own; on the
  // open ground the walk is the one without a width.
  Character wide = LoadShipped("biped");
  REQUIRE(wide.foot_width > 0);
  Character narrow = wide;
  narrow.foot_width = 0;
  const double s = 0.03;
  RawSamples ground;
  for (int i = 0; i * s <= 2 + 1e-9; ++i)
    for (int k = 0; k * s <= 8 + 1e-9; ++k) ground.push_back({i * s, 0, k * s}, {0, 1, 0});
  Terrain t = LoadTerrain(ground, s);
  const double edge = (static_cast<int>((2 + 1e-9) / s)) * s;  // the last column of samples
  const double half = 0.5 * wide.foot_width;
  for (const double x : {edge - 0.12 - 0.01, 1.0}) {
    GenerateOptions o = StartOptions({x, 0, 0.5}, 8);
    o.heading = {0, 0, 1};
    const Walk w = Generate(t, wide, o), v = Generate(t, narrow, o);
    INFO("start x " << x << ": " << w.stopped);
    CheckWalk(t, wide, o, w);
    CHECK(w.stopped.empty());
    double widest = 0, widest_narrow = 0;
    for (const Walk* walk : {&w, &v})
      for (const WalkTrack& tr : walk->tracks)
        if (tr.kind == TrackKind::kFoot)
          for (const WalkKey& k : tr.keys)
            if (k.phase != KeyPhase::kMid)
              (walk == &w ? widest : widest_narrow) =
                  std::max(walk == &w ? widest : widest_narrow, k.position.x + half);
    if (x > 1.5) {                      // beside the edge
      CHECK(widest_narrow > edge + s);  // hangs past the edge by more than a spacing
      CHECK(widest <= edge + s);        // ground within a spacing under the side
    } else {
      CHECK(widest == widest_narrow);
      REQUIRE(w.tracks.size() == v.tracks.size());
      for (size_t i = 0; i < w.tracks.size(); ++i)
        for (size_t j = 0; j < w.tracks[i].keys.size() && j < v.tracks[i].keys.size(); ++j)
          CHECK(w.tracks[i].keys[j].position == v.tracks[i].keys[j].position);
    }
  }
}

TEST_CASE("A biped with a foot width walks a beam narrower than its stance with both soles on it",
          "[steps][generator][soles]") {
  // A beam 24 cm wide (9 columns of 3 cm samples), the biped's feet 24 cm apart at rest: each
  // sole's outer side hung 5 cm off the beam. Both feet now step in until it has ground.
  Character wide = LoadShipped("biped");
  Character narrow = wide;
  narrow.foot_width = 0;
  const double s = 0.03, x0 = 1, x1 = 1 + 8 * s;
  RawSamples beam;
  for (int i = 0; i <= 8; ++i)
    for (int k = 0; k <= 200; ++k) beam.push_back({x0 + i * s, 1, k * s}, {0, 1, 0});
  Terrain t = LoadTerrain(beam, s);
  GenerateOptions o = StartOptions({0.5 * (x0 + x1), 1, 0.3}, 8);
  o.heading = {0, 0, 1};
  const double half = 0.5 * wide.foot_width;
  for (const Character* c : {&wide, &narrow}) {
    const Walk w = Generate(t, *c, o);
    INFO((c == &wide ? "with a width: " : "without: ") << w.stopped);
    CheckWalk(t, *c, o, w);
    CHECK(w.stopped.empty());
    double overhang = 0;  // the most a sole's side lies past the beam's samples
    int keys = 0;
    for (const WalkTrack& tr : w.tracks)
      if (tr.kind == TrackKind::kFoot)
        for (const WalkKey& k : tr.keys)
          if (k.phase != KeyPhase::kMid)
            ++keys, overhang =
                        std::max({overhang, x0 - (k.position.x - half), k.position.x + half - x1});
    CHECK(keys >= 9);
    if (c == &wide)
      CHECK(overhang <= s);  // ground within a spacing under each side
    else
      CHECK(overhang > s);
  }
}

TEST_CASE("A walk's foot tracks carry their character's foot length", "[steps][generator][soles]") {
  // (For the viewer, which draws each sole as long as its track says.)
  const Character shipped = LoadShipped("biped");
  REQUIRE(shipped.foot_length > 0);
  Character point = shipped;
  point.foot_length = 0;
  Terrain flat = LoadTerrain(MakeFlat(201, 0.05, 0), 0.05);
  const GenerateOptions one = StartOptions(Vec3{3, 0, 1}, 2);
  const GenerateOptions crowd = CrowdOptions(Vec3{5, 0, 3}, 2, 3, 1.0);
  for (const GenerateOptions* o : {&one, &crowd}) {
    for (const Character* c : {&shipped, static_cast<const Character*>(&point)}) {
      const Walk w = Generate(flat, *c, *o);
      size_t feet = 0;
      for (const WalkTrack& t : w.tracks) {
        INFO(t.character << " " << t.name);
        CHECK(t.foot_length == (t.kind == TrackKind::kFoot ? c->foot_length : 0));
        CHECK(t.foot_width ==
              (t.kind == TrackKind::kFoot && c->foot_length > 0 ? c->foot_width : 0));
        feet += t.kind == TrackKind::kFoot;
      }
      CHECK(feet == c->feet.size() * (o == &crowd ? 3 : 1));
      const std::string text = WalkToJson(w);
      CHECK((text.find("\"foot_length\":0.22,") != std::string::npos) == (c == &shipped));
      CHECK((text.find("\"foot_width\":0.1,") != std::string::npos) == (c == &shipped));
    }
  }
}
