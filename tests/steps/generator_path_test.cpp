// The step generator's heading and paths: any heading, a path with a 90-degree turn, goals
// behind and inside the turning circle, feet keeping their sides in turns, dead ends.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <set>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/import/mesh_generators.h"
#include "footfall/import/mesh_sampler.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/import/terrain_loader.h"
#include "generator_fixtures.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

TEST_CASE("Any heading, not only +Z", "[steps][generator]") {
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(200, 0.05, 0), 0.05);
  GenerateOptions o;
  o.has_start = true;
  o.start = {3, 0, 3};
  o.heading = {1, 0.5, -1};  // projected onto the ground: (1, 0, -1)
  o.steps = 8;
  const Walk w = Generate(t, c, o);
  REQUIRE(w.stopped.empty());
  CheckWalk(t, c, o, w);
  const auto& body = Body(w).keys;
  const Vec3 moved = body.back().position - body.front().position;
  const Vec3 want = Normalize(Vec3{1, 0, -1});
  CHECK(Dot(Normalize(moved), want) > 0.99);
  CHECK(Dot(BodyForward(Body(w).rotations.back()), want) > 0.999);
}

TEST_CASE("A biped heading across a cliff's edge stops there, not crabbing along it",
          "[steps][generator]") {
  // Heading at 30 to 60 degrees to the edge of a flat terrain (8 m, 4 cm samples), the biped
  // reached the edge and walked along it, facing the drop, its feet closing in on each other.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(200, 0.04, 0), 0.04);
  for (const double degrees : {30.0, 45.0, 60.0}) {
    INFO(degrees << " degrees to the edge at z = 7.96");
    const double r = degrees * kPi / 180;
    GenerateOptions o = StartOptions({2, 0, 6}, 24);
    o.heading = {std::cos(r), 0, std::sin(r)};
    const Walk walk = Generate(t, c, o);
    CheckWalk(t, c, o, walk);
    CHECK_THAT(walk.stopped, Catch::Contains("the terrain ends"));
    // Every step of the body goes the way it faces (within the 40 degrees a foothold may lie
    // aside of its step).
    const auto& keys = Body(walk).keys;
    const auto& turns = Body(walk).rotations;
    REQUIRE(keys.size() > 3);
    for (size_t i = 1; i < keys.size(); ++i) {
      const Vec3 moved = keys[i].position - keys[i - 1].position;
      if (Length(moved) < 0.02) continue;
      INFO("body key " << i << " moved " << Length(moved));
      CHECK(Dot(Normalize(moved), BodyForward(turns[i])) > std::cos(45 * kPi / 180));
    }
  }
}

TEST_CASE("The heading follows a path with a 90-degree turn", "[steps][generator]") {
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double leg = 10 * c.step_length, margin = 4 * c.reach;
    Terrain t = FlatFor(c, leg + 2 * margin);
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = {margin, 0, margin};
    o.heading = {0, 0, 1};
    const Vec3 corner{margin, 0, margin + leg}, goal{margin + leg, 0, margin + leg};
    o.path = {corner, goal};
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    REQUIRE(w.stopped.empty());
    CheckWalk(t, c, o, w);
    const auto& body = Body(w).keys;
    const Vec3 ground_end = body.back().position - Vec3{0, c.body_height, 0};
    CHECK(Distance(ground_end, goal) <= c.step_length);
    bool faced_z = false, faced_x = false;
    double nearest_corner = 1e9;
    for (size_t i = 0; i < body.size(); ++i) {
      const WalkKey& k = body[i];
      const Vec3 f = BodyForward(Body(w).Rotation(i));
      faced_z |= f.z > 0.99;
      faced_x |= f.x > 0.99;
      nearest_corner =
          std::min(nearest_corner, Distance(k.position - Vec3{0, c.body_height, 0}, corner));
      // Before the corner it walks +Z; after, +X; never back (small corrections aside).
      CHECK(f.x > -0.1);
      CHECK(f.z > -0.1);
    }
    CHECK(faced_z);
    CHECK(faced_x);
    CHECK(BodyForward(Body(w).rotations.back()).x > 0.99);
    CHECK(nearest_corner < 2 * c.step_length);
  }
}

TEST_CASE("A path drawn from where the character stands starts facing its next waypoint",
          "[steps][generator]") {
  // A path whose first waypoint is the start gave no direction there: the walk set off along
  // the default heading (+Z) and turned round toward the goal behind it.
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double leg = 8 * c.step_length, margin = 4 * c.reach;
    Terrain t = FlatFor(c, leg + 2 * margin);
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = {margin + leg, 0, margin};
    o.path.push_back(o.start);
    o.path.push_back(Vec3{margin, 0, margin});
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    REQUIRE(w.stopped.empty());
    CheckWalk(t, c, o, w);
    // Every key of the body faces -X, the first too.
    for (size_t i = 0; i < Body(w).keys.size(); ++i)
      CHECK(BodyForward(Body(w).Rotation(i)).x < -0.99);
  }
}

TEST_CASE("A character that turns slowly reaches a goal behind it by most of a circle",
          "[steps][generator]") {
  // At 2 degrees a step, a goal ten steps behind is neared again only after some 150 steps
  // round a circle of ~29 steps' radius: the walk stopped as a dead end after 100.
  for (const std::string& name : ShippedCharacters()) {
    Character c = LoadShipped(name);
    c.max_turn_deg = 2;
    const double step = c.step_length, spacing = step / 3, side = 140 * step;
    Terrain t = LoadTerrain(MakeFlat(static_cast<int>(side / spacing), spacing, 0), spacing);
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = {side / 2, 0, side / 2};
    const Vec3 goal = o.start;
    o.path.push_back(o.start + Vec3{0, 0, 10 * step});
    o.path.push_back(goal);
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    REQUIRE(w.stopped.empty());
    const Vec3 ground_end = Body(w).keys.back().position - Vec3{0, c.body_height, 0};
    CHECK(Distance(ground_end, goal) <= step);
  }
}

TEST_CASE("A character that turns very slowly reaches a goal it starts facing",
          "[steps][generator]") {
  // With max_turn_deg 0.1 its full-stride circle is ~200 m wide: the goal, a few centimetres
  // aside once the feet had snapped to the samples, lay inside it, and the strides shrank to
  // nothing; the biped shuffled sideways for 1000 steps. Within half a step of that circle, the
  // goal is reached at full stride.
  Character c = LoadShipped("biped");
  c.max_turn_deg = 0.1;
  RawSamples hills;
  std::string error;
  REQUIRE(footfall::LoadTerrain(std::string(FOOTFALL_SOURCE_DIR) + "/data/terrain/hills.pts",
                                TerrainLoadOptions{}, &hills, &error) == Status::kOk);
  Terrain t = LoadTerrain(hills, 0.25);
  GenerateOptions o;
  o.has_start = true;
  o.start = {20, 0, 20};
  const Vec3 goal{25, 0, 25};
  o.path = {goal};
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  REQUIRE(w.stopped.empty());
  const Vec3 end = Body(w).keys.back().position;
  CHECK(std::hypot(end.x - goal.x, end.z - goal.z) <= 0.5 * c.step_length);
  CHECK(StepsDone(w) <= 2 * std::hypot(5.0, 5.0) / c.step_length + 4);
}

TEST_CASE("A waypoint inside the turning circle is reached with shorter steps, not circled",
          "[steps][generator]") {
  // The shipped biped with --path "0,0,3 0.5,0,2.5" turned 30 degrees a step at full stride
  // about a goal inside its turning circle (radius ~0.67 m) for 10,000 steps, never within half
  // a step of it. The same with every character and a smaller max_turn_deg, and with the
  // waypoint beside the corner as an intermediate one.
  for (const std::string& name : ShippedCharacters()) {
    for (const double turn : {30.0, 15.0}) {
      for (const bool intermediate : {false, true}) {
        Character c = LoadShipped(name);
        c.max_turn_deg = turn;
        const double step = c.step_length, spacing = step / 10, margin = 4 * c.reach;
        const int n = static_cast<int>((10 * step + 2 * margin) / spacing);
        Terrain t = LoadTerrain(MakeFlat(n, spacing, 0), spacing);
        INFO(name << ", max_turn_deg " << turn << (intermediate ? ", intermediate" : ""));
        GenerateOptions o;
        o.has_start = true;
        o.start = {margin, 0, margin};
        const Vec3 corner{margin, 0, margin + 4 * step};
        const Vec3 beside = corner + Vec3{0.7 * step, 0, -0.7 * step};
        const Vec3 goal = intermediate ? beside + Vec3{0, 0, 4 * step} : beside;
        o.path.push_back(corner);
        o.path.push_back(beside);
        if (intermediate) o.path.push_back(goal);
        const Walk w = Generate(t, c, o);
        INFO(w.stopped);
        REQUIRE(w.stopped.empty());
        CheckWalk(t, c, o, w);
        // About 15 steps of path: well within 80 steps, not 10,000.
        CHECK(StepsDone(w) < 80);
        Vec3 centroid;
        int feet = 0;
        double nearest_beside = 1e9;
        for (const WalkTrack& tr : w.tracks) {
          if (tr.kind != TrackKind::kFoot) continue;
          centroid += tr.keys.back().position, ++feet;
        }
        for (const WalkKey& k : Body(w).keys)
          nearest_beside =
              std::min(nearest_beside, Distance(k.position - Vec3{0, c.body_height, 0}, beside));
        CHECK(Distance(centroid / static_cast<double>(feet), goal) <= 0.5 * step + 1e-9);
        CHECK(nearest_beside <= step + 1e-9);
      }
    }
  }
}

namespace {

// The least gap across the body's heading between the feet of a pair, over every body key, as
// a share of their gap at rest (below 0: a pair's feet crossed under the body).
double LeastPairGap(const Character& c, const Walk& w) {
  const std::vector<const WalkTrack*> tracks = TracksOf(w, "");
  const WalkTrack& body = *tracks.back();
  double least = 1e9;
  for (size_t i = 0; i < body.keys.size(); ++i) {
    const Quat q = body.Rotation(i);
    const Vec3 left = Cross(BodyUp(q), BodyForward(q));
    for (const std::vector<int>& pair : c.pairs) {
      if (pair.size() != 2) continue;
      const double rest_gap = c.feet[pair[0]].rest.x - c.feet[pair[1]].rest.x;
      const Vec3 a = FootAt(*tracks[pair[0]], body.keys[i].frame);
      const Vec3 b = FootAt(*tracks[pair[1]], body.keys[i].frame);
      least = std::min(least, Dot(a - b, left) / rest_gap);
    }
  }
  return least;
}

}  // namespace

TEST_CASE("Feet keep to their sides in sharp turns as the body turns no faster than they follow",
          "[steps][generator]") {
  // Turning max_turn_deg a step, a multiped's feet (a step_length a step, each foot every other
  // step) fell behind the body until a pair's feet crossed under it: the shipped hexapod at its
  // 30 degrees, about a hairpin; a biped or quadruped allowed 60 to 180 degrees a step crossed
  // its feet at a right-angle corner.
  for (const std::string& name : ShippedCharacters()) {
    for (const double turn : {30.0, 90.0, 180.0}) {
      for (const int shape : {0, 1, 2, 3}) {
        // A hairpin or a right angle, with the shipped pairs or without (each foot its own):
        // then each foot keeps to its side of the foot whose rest mirrors its own.
        const bool hairpin = shape % 2 == 0, paired = shape < 2;
        const Character shipped = LoadShipped(name);
        Character c = shipped;
        c.max_turn_deg = turn;
        if (!paired) {
          c.pairs.clear();
          for (int f = 0; f < static_cast<int>(c.feet.size()); ++f) c.pairs.push_back({f});
        }
        const double step = c.step_length, spacing = step / 10, margin = 4 * c.reach;
        const int n = static_cast<int>((8 * step + 2 * margin) / spacing);
        Terrain t = LoadTerrain(MakeFlat(n, spacing, 0), spacing);
        INFO(name << ", max_turn_deg " << turn << (hairpin ? ", hairpin" : ", right angle")
                  << (paired ? "" : ", no pairs"));
        GenerateOptions o;
        o.has_start = true;
        o.start = {margin + 4 * step, 0, margin};
        const Vec3 corner = o.start + Vec3{0, 0, (hairpin ? 6 : 3) * step};
        o.path.push_back(corner);
        o.path.push_back(hairpin ? o.start + Vec3{0.3 * step, 0, 0}
                                 : corner + Vec3{4 * step, 0, 0});
        const Walk w = Generate(t, c, o);
        INFO(w.stopped);
        REQUIRE(w.stopped.empty());
        CheckWalk(t, c, o, w);
        CHECK(LeastPairGap(shipped, w) > 0.1);
      }
    }
  }
}

TEST_CASE("Feet on ground sampled about as far apart as they stand keep to their own sides",
          "[steps][generator]") {
  // The main job's biped (feet 0.2 m apart) on the bundled hills' 0.25 m lattice: walking along
  // a column of samples both feet took it, and on the diagonal leg a foot often took a sample
  // across the other's (34 of 130 body keys). Each foothold lined up so is asked again aimed
  // outward (to three quarters of the rest gap, and at least half the spacing).
  const Character c = LoadShipped("biped");
  const double spacing = 0.25;
  Terrain t = LoadTerrain(MakeFlat(121, spacing, 0), spacing);
  for (const bool diagonal : {false, true}) {
    INFO((diagonal ? "diagonal" : "along a column"));
    GenerateOptions o;
    o.has_start = true;
    o.start = {8, 0, 8};
    o.path.push_back({8, 0, 20});
    if (diagonal) o.path.push_back({20, 0, 28});
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    REQUIRE(w.stopped.empty());
    CheckWalk(t, c, o, w);
    CHECK(LeastPairGap(c, w) > 0.25);
  }
  // Along the bundled hills' edge (x = 40), the right foot on its last column: the left foot's
  // retry, aimed to three quarters of the rest gap outward, lies off the terrain, and the
  // sample it found crossed the other foot (four times in 16 steps) until such a retry is asked
  // once more half a spacing outward.
  Terrain hills = LoadTerrain(LoadShippedTerrain("hills"), 0.25);
  GenerateOptions o = StartOptions({40, 0, 9.75}, 16);
  o.heading = {0.68005, 0, 0.73317};
  const Walk w = Generate(hills, c, o);
  INFO("along the hills' edge: " << w.stopped);
  CheckWalk(hills, c, o, w);
  CHECK(LeastPairGap(c, w) >= -0.01);
}

TEST_CASE("A foot with no foothold while its character turns on the spot keeps its place",
          "[steps][generator]") {
  // The shipped octopod turning about a goal behind it at the foot of the shipped stairs: a hind
  // foot by the first riser, its target below the floor at the riser's foot, found no foothold
  // and stopped the walk at step 168; it stands where it is until the turn takes it on.
  Terrain t = LoadTerrain(LoadShippedTerrain("stairs"), 0.03);
  const Character c = LoadShipped("octopod");
  GenerateOptions o;
  o.has_start = true;
  o.start = {0.434568, 5, 0.668211};
  o.path.push_back({1.04996, 0, 0.823702});
  o.path.push_back({0.525957, 0, 0.261477});
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
}

TEST_CASE("A path walk that runs out of steps before its goal says so as a stop",
          "[steps][generator]") {
  // Back and forth between two points 4 m apart, 2000 times: more than the 10,000 steps a path
  // walk takes without --steps (it ended there with no word, as if it had arrived).
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(200, 0.05, 0), 0.05);
  GenerateOptions o;
  o.has_start = true;
  o.start = {5, 0, 2};
  for (int i = 0; i < 2000; ++i) o.path.push_back({5, 0, i % 2 ? 2.0 : 8.0});
  const Walk w = Generate(t, c, o);
  // How far along the path, not only in a straight line (1000 legs of 6 m are left).
  CHECK_THAT(w.stopped, Catch::StartsWith("step 10001: the path's goal (5.0000, 0.0000, 2.0000) "
                                          "is still ") &&
                            Catch::Contains(" away along the path (") &&
                            Catch::EndsWith("after 10000 steps, the most a path walk takes "
                                            "without a step count (--steps; give one to walk "
                                            "farther); walk stopped, keys up to step 10000 kept"));
  CHECK(StepsDone(w) == 10000);
  // With --steps the walk is as asked: no stop, but a note of how far the goal still is (it
  // ended short of it saying nothing).
  o.steps = 50;
  const Walk asked = Generate(t, c, o);
  CHECK(asked.stopped.empty());
  REQUIRE(asked.notes.size() == 1);
  CHECK_THAT(asked.notes[0],
             Catch::StartsWith("the path's goal (5.0000, 0.0000, 2.0000) is still ") &&
                 Catch::Contains(" away along the path (") &&
                 Catch::EndsWith(" in a straight line) after the 50 steps asked for (without a "
                                 "step count, --steps, a path walk goes on to its goal, up to "
                                 "10000 steps)"));
  // 1999 legs of 6 m after the one under way: every digit, no exponent.
  CHECK_THAT(asked.notes[0], Catch::Matches(".* is still 1[12][0-9]{3} away along the path .*"));
  // Steps enough to arrive: nothing to say.
  o.path = {{5, 0, 4}};
  CHECK(Generate(t, c, o).notes.empty());
  // Arriving with the last step asked for: nothing either.
  o.steps = static_cast<int>(StepsDone(Generate(t, c, o)));
  const Walk just = Generate(t, c, o);
  CHECK(just.stopped.empty());
  CHECK(just.notes.empty());
  o.steps -= 1;
  CHECK(Generate(t, c, o).notes.size() == 1);
}

namespace {

// A three-legged character with its feet off the body's centre line, each in a gait group of
// its own (a dead end's test subject: it shuffles its feet about a spot easily).
Character Asymmetric() {
  Character asym;
  std::string error;
  REQUIRE(ParseCharacter(R"({"format": "footfall-character", "version": 1, "name": "asym",
    "feet": [{"name": "L", "rest": [0.3, 0, 0.1]}, {"name": "R", "rest": [-0.1, 0, -0.2]},
             {"name": "T", "rest": [0.05, 0, -0.6]}],
    "gait": [["L"], ["R"], ["T"]], "step_length": 0.4, "step_height": 0.1, "body_height": 0.45,
    "frames_per_step": 8, "align_to_normal": true, "max_rise": 0.25, "reach": 1.0,
    "max_slope_deg": 50})",
                         "asym", &asym, &error) == Status::kOk);
  return asym;
}

}  // namespace

TEST_CASE("A path given at y = 0 is followed over a DEM hundreds of metres up",
          "[steps][generator][shared-data]") {
  // Real data from ../shared/data: the Kootenai DEM (537 to 560 m) resampled at 0.175. The
  // three-legged character's up leans with the ground, and its waypoints at y = 0 were aimed
  // at along it: it shuffled its feet about the same spot until a dead end stopped it.
  const std::string path =
      FOOTFALL_SOURCE_DIR "/../shared/data/terrain/terrain_kootenai_1m_50x37.asc";
  std::ifstream probe(path);
  if (!probe) {
    if (std::getenv("CI")) FAIL("shared data missing in CI: " << path);
    WARN("skipped: shared data not found at " << path << " (CI is unset)");
    return;
  }
  RawSamples dem;
  std::string error;
  TerrainLoadOptions lo;
  lo.separation = 0.175;
  REQUIRE(footfall::LoadTerrain(path, lo, &dem, &error) == Status::kOk);
  Terrain t = LoadTerrain(dem, 0.175);
  const Character asym = Asymmetric();
  GenerateOptions o;
  o.has_start = true;
  o.start = {14.7, 0, 9};
  o.path = {{14.7, 0, 25.2}, {34.3, 0, 25.2}, {34.3, 0, 10.8}, {22.05, 0, 16.2}};
  o.steps = 5000;
  const Walk w = Generate(t, asym, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, asym, o, w);
  Vec3 centroid;
  for (const WalkTrack& tr : w.tracks)
    if (tr.kind == TrackKind::kFoot) centroid += tr.keys.back().position / 3.0;
  CHECK(std::hypot(centroid.x - 22.05, centroid.z - 16.2) <= 0.5 * asym.step_length + 1e-9);
}

TEST_CASE("A character milling about at a dead end stops", "[steps][generator]") {
  // The three-legged character on a table top, its goal on the floor 0.9 m below it with no way
  // down: it turns and shuffles about on the top, coming no nearer, and stops within a few
  // hundred steps, not after every step it was given.
  const Character asym = Asymmetric();
  RawSamples s = MakeFlat(160, 0.05, 0);
  for (int k = 0; k <= 60; ++k)
    for (int i = 0; i <= 60; ++i) s.push_back({2 + i * 0.05, 0.9, 2 + k * 0.05}, {0, 1, 0});
  Terrain t = LoadTerrain(s, 0.05);
  GenerateOptions o;
  o.has_start = true;
  o.start = {3.5, 1, 3.5};
  o.path = {{3.6, 0, 3.5}};
  o.steps = 5000;
  const Walk w = Generate(t, asym, o);
  INFO(w.stopped);
  CHECK_THAT(w.stopped, Catch::Contains("the body has stayed within half a step of it for 100 "
                                        "steps (a dead end)") ||
                            Catch::Contains("no way to the path's goal (3.6000, 0.0000, 3.5000): "
                                            "the body has come no nearer to it than"));
  CHECK(StepsDone(w) < 2000);
  CheckWalk(t, asym, o, w);
}

TEST_CASE("A walk along a loop that comes back to where it was a dead-end window before goes on",
          "[steps][generator]") {
  // The shipped biped around a square of 8.8 m sides and up its first side again: at step 100,
  // the dead-end window's length, its body was back within half a step of its start, and the
  // walk stopped as milling about at a dead end.
  const Character c = LoadShipped("biped");
  const double spacing = 0.05;
  Terrain t = LoadTerrain(MakeFlat(361, spacing, 0), spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {5, 0, 5};
  const double far = 5 + 8.8;
  o.path.push_back({5, 0, far});
  o.path.push_back({far, 0, far});
  o.path.push_back({far, 0, 5});
  o.path.push_back({5, 0, 5});
  o.path.push_back({5, 0, far});
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CHECK(StepsDone(w) > 100);
  CheckWalk(t, c, o, w);
}

TEST_CASE("A path walk on rocky ground turned about a slanting axis is the same walk turned",
          "[steps][generator]") {
  // The terrain's sample spacing, by which swing arcs are checked, read 8 to 15% wider on
  // ground turned 37 degrees: the same biped walk raised a mid key in one and not the other,
  // and the walks parted by up to 0.84 m here. (The spacing still varies by a per cent or two
  // with the turn, so a walk on other ground may still part where an arc is borderline.)
  const Character c = LoadShipped("biped");
  const RawSamples rocks = MakeRocks(8, 0.6, 0.05, 1);
  REQUIRE(rocks.size() > 0);
  const Vec3 axis = Normalize(Vec3{1, 2, 3});
  const double a = 37 * kPi / 180;
  auto turn = [&](const Vec3& v) {  // Rodrigues' rotation about `axis`
    return v * std::cos(a) + Cross(axis, v) * std::sin(a) +
           axis * (Dot(axis, v) * (1 - std::cos(a)));
  };
  RawSamples turned;
  for (size_t i = 0; i < rocks.size(); ++i)
    turned.push_back(turn(rocks.points[i]), turn(rocks.normals[i]));
  GenerateOptions o;
  o.has_start = true;
  o.start = {1, 0.6, 1};
  o.path = {{4, 0.6, 1}, {4, 0.6, 4}, {2, 0.6, 5}, {6, 0.6, 6}, {6, 0.6, 2}};
  GenerateOptions ot = o;
  ot.start = turn(o.start);
  for (Vec3& p : ot.path) p = turn(p);
  ot.up = turn(o.up);
  Terrain t = LoadTerrain(rocks, 0.05), tt = LoadTerrain(turned, 0.05);
  const Walk w = Generate(t, c, o), wt = Generate(tt, c, ot);
  CHECK(w.stopped == wt.stopped);
  REQUIRE(w.tracks.size() == wt.tracks.size());
  double worst = 0;
  size_t keys = 0;
  for (size_t k = 0; k < w.tracks.size(); ++k) {
    REQUIRE(w.tracks[k].keys.size() == wt.tracks[k].keys.size());
    for (size_t i = 0; i < w.tracks[k].keys.size(); ++i, ++keys) {
      CHECK(w.tracks[k].keys[i].frame == wt.tracks[k].keys[i].frame);
      worst = std::max(worst,
                       Length(turn(w.tracks[k].keys[i].position) - wt.tracks[k].keys[i].position));
    }
  }
  INFO(keys << " keys, the farthest apart " << worst);
  CHECK(keys > 100);
  CHECK(worst < 1e-5);
}

TEST_CASE("A path walk without a step count that arrives on its last step has arrived",
          "[steps][generator][path]") {
  // A strip 3.6 km long; the biped walks kMaxPathSteps steps along it toward goals about as far
  // as that takes it. Without a step count it walks those steps at most, so it arrives exactly
  // when the same walk given kMaxPathSteps does (an arrival on the last step was said as a
  // stop: "still 0.15 away", within the arrival radius).
  RawSamples s;
  for (int j = 0; j <= 36000; ++j)
    for (int i = 0; i < 13; ++i) s.push_back({i * 0.1, 0, j * 0.1}, {0, 1, 0});
  Terrain t = LoadTerrain(s, 0.1);
  const Character c = LoadShipped("biped");
  int arrived_last = 0;
  for (const double goal : {3500.6, 3501.0, 3501.2, 3501.5}) {
    INFO("goal at z = " << goal);
    GenerateOptions o;
    o.has_start = true;
    o.start = {0.6, 0, 1};
    o.path = {{0.6, 0, goal}};
    const Walk open = Generate(t, c, o);
    o.steps = kMaxPathSteps;
    const Walk counted = Generate(t, c, o);
    bool short_of_goal = false;
    for (const std::string& note : counted.notes)
      short_of_goal |= note.find("is still") != std::string::npos;
    CHECK(open.stopped.empty() == !short_of_goal);
    arrived_last += !short_of_goal && StepsDone(counted) == static_cast<size_t>(kMaxPathSteps);
    CHECK(StepsDone(open) == StepsDone(counted));
  }
  CHECK(arrived_last >= 1);  // one goal is reached by the last step exactly
}

namespace {

// Ground along +z sampled `s` apart, `width` wide from x = 0: level at y = height(z), its
// normals from the slope height'(z) (numerically).
template <typename Height>
RawSamples GroundAlongZ(double s, double width, double length, const Height& height) {
  RawSamples g;
  for (double z = 0; z <= length + 1e-9; z += s) {
    const double slope = (height(z + 1e-4) - height(z - 1e-4)) / 2e-4;
    for (double x = 0; x <= width + 1e-9; x += s)
      g.points.push_back({x, height(z), z}), g.normals.push_back(Normalize(Vec3{0, 1, -slope}));
  }
  return g;
}

}  // namespace

TEST_CASE("A 2D goal is neared across the world up, whatever a multiped's up leans",
          "[steps][generator]") {
  // A hexapod up a 45-degree ramp onto a plateau 30 m long, its goal at y = -5 (off the
  // terrain). Its distance was measured across its own up: on the ramp, leaning toward the
  // goal, 0.7 of the level distance; 100 steps on the plateau could not beat it, and the walk
  // stopped with "no way to the path's goal" while it came nearer at every step.
  const Character c = LoadShipped("hexapod");
  const double s = 0.03;
  auto height = [](double z) { return std::clamp(z - 1.0, 0.0, 0.5); };
  Terrain t = LoadTerrain(GroundAlongZ(s, 0.9, 32, height), s);
  const GenerateOptions o = PathOptions({0.45, 0, 0.4}, {{0.45, -5, 31.5}}, 3000);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  const Vec3 end = Body(w).keys.back().position;
  CHECK(std::hypot(end.x - 0.45, end.z - 31.5) <= c.step_length);
}

TEST_CASE("A multiped walks a straight 2D path straight across a side slope",
          "[steps][generator]") {
  // A hexapod along +z across a slope rising 30 degrees toward +x, its goal given at y = 0
  // (off the slope, as a 2D path is). The level offset to the goal was laid onto the ground
  // along the hexapod's tilted up, which turns it toward the contour seen from above: on made
  // hills it walked up to 33 degrees off a straight path and 1.8 m aside of it. Laid along the
  // world up, it keeps to the line.
  const Character c = LoadShipped("hexapod");
  const double s = 0.03, rise = std::tan(30 * kPi / 180);
  RawSamples g;
  for (double z = 0; z <= 12 + 1e-9; z += s)
    for (double x = 0; x <= 4 + 1e-9; x += s)
      g.points.push_back({x, rise * x, z}), g.normals.push_back(Normalize(Vec3{-rise, 1, 0}));
  Terrain t = LoadTerrain(g, s);
  for (const double goal_x : {1.0, 3.5}) {  // along the contour, and 2.5 m uphill across it
    GenerateOptions o;
    o.has_start = true;
    o.start = {1.0, rise * 1.0, 0.5};
    o.heading = {goal_x - 1.0, 0, 11};
    o.path = {{goal_x, 0, 11.5}};
    o.steps = 1000;
    const Walk w = Generate(t, c, o);
    INFO("goal x " << goal_x << ": " << w.stopped);
    CHECK(w.stopped.empty());
    CheckWalk(t, c, o, w);
    double aside = 0;  // the body's farthest from the straight line to the goal, seen from above
    for (const WalkKey& k : Body(w).keys) {
      const double along = (k.position.z - 0.5) / 11;
      aside = std::max(aside, std::fabs(k.position.x - (1.0 + along * (goal_x - 1.0))));
    }
    CHECK(aside < 0.15);  // (0.25 across it, before)
  }
}

TEST_CASE("A slow-turning biped turns on the spot to a corner it cannot circle in samples",
          "[steps][generator]") {
  // A biped turning 1 degree a step on ground sampled every 5 cm, its path turning 90 degrees:
  // the circle through the corner asked for strides of a centimetre, which the feet walked as
  // steps in place or a whole sample on, and the body circled the goal 0.6 m off for 370 steps
  // until the walk stopped with "no way". It turns on the spot instead until the goal is ahead.
  Character c = LoadShipped("biped");
  c.max_turn_deg = 1;
  Terrain t = LoadTerrain(MakeFlat(401, 0.05, 0), 0.05);
  const GenerateOptions o = PathOptions({10, 0, 10}, {{10, 0, 13}, {13, 0, 13}}, 2000);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
  const Vec3 end = Body(w).keys.back().position;
  CHECK(std::hypot(end.x - 13, end.z - 13) <= 0.5 * c.step_length + 1e-9);
}

TEST_CASE("A 2D goal below a steep ramp is neared as seen from above", "[steps][generator]") {
  // A hexapod down a 65-degree ramp 300 m up, its goal at y = 0 past the ramp's foot. On ground
  // steeper than a floor the goal is measured across the hexapod's up, where the 300 m of
  // height outweighs the way walked: coming 2.4 m nearer seen from above, it was stopped for
  // "no way to the path's goal".
  const Character c = LoadShipped("hexapod");
  const double s = 0.025;
  RawSamples ramp = MakeRamps({65, 30}, 3, 1.5, s);
  for (Vec3& p : ramp.points) p.y += 300;
  Terrain t = LoadTerrain(ramp, s);
  const GenerateOptions o = PathOptions({0.75, 0, 10.5}, {{0.75, 0, 1}}, 1000);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
  const Vec3 end = Body(w).keys.back().position;
  CHECK(std::hypot(end.x - 0.75, end.z - 1) <= c.step_length);
}

TEST_CASE("A multiped walks straight to a goal on far hilly ground", "[steps][generator]") {
  // A quadruped across hills to a goal 22 m off on the ground. The goal's direction, laid onto
  // the quadruped's ground along its up, turned toward the contour wherever the ground between
  // leaned: its track bowed 1 m off the line (on the Kootenai DEM a hexapod's bowed 1.3 m).
  // Seen from above, it keeps to it.
  const Character c = LoadShipped("quadruped");
  const int n = 241;  // 24 m at 0.1
  const RawSamples hills = MakeHills(n, 0.1, 1.0, 2);
  Terrain t = LoadTerrain(hills, 0.1);
  const Vec3 from = hills.points[10 * n + 120], to = hills.points[230 * n + 120];
  REQUIRE(from.x == Approx(12));
  REQUIRE(to.z == Approx(23));
  const GenerateOptions o = PathOptions(from, {to}, 1000);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
  double aside = 0;  // seen from above, from the line x = 12
  for (const WalkKey& k : Body(w).keys) aside = std::max(aside, std::fabs(k.position.x - 12));
  CHECK(aside < 0.5);
}
