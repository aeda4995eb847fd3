// The step generator's start: the default start, a start moved to where the character can
// stand, feet that snap onto one sample, a crowd's grid across a box.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/import/mesh_generators.h"
#include "footfall/import/mesh_sampler.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/steps/generate_request.h"
#include "generator_fixtures.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

TEST_CASE("Feet that snap onto one sample at the start take their own", "[steps][generator]") {
  // Ground sampled 0.25 apart, coarser than the biped's stance (0.24): started on a sample,
  // both feet snapped onto it (the bundled hills walk began so). On a beam one sample wide they
  // still share it (the stance narrows).
  const Character c = LoadShipped("biped");
  GenerateOptions o;
  o.has_start = true;
  o.start = {5, 0, 5};
  o.steps = 4;
  {
    Terrain t = LoadTerrain(MakeFlat(41, 0.25, 0), 0.25);
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    std::vector<Vec3> starts;
    for (const WalkTrack& track : w.tracks)
      if (track.kind == TrackKind::kFoot) starts.push_back(track.keys.front().position);
    REQUIRE(starts.size() == 2);
    CHECK(Distance(starts[0], starts[1]) == Approx(0.25));
  }
  {
    RawSamples beam;
    for (int k = 0; k <= 80; ++k) beam.push_back({5, 0, 0.125 * k}, {0, 1, 0});
    Terrain t = LoadTerrain(beam, 0.125);
    const Walk w = Generate(t, c, o);
    std::vector<Vec3> starts;
    for (const WalkTrack& track : w.tracks)
      if (track.kind == TrackKind::kFoot) starts.push_back(track.keys.front().position);
    REQUIRE(starts.size() == 2);
    CHECK(Distance(starts[0], starts[1]) == 0);
  }
}

TEST_CASE("A start beside a box's foot stands on the floor, a crowd's grid across it",
          "[steps][generator]") {
  // A floor sampled every 4 cm and a box (0.25 m tall, from z = 2) whose front face, sampled
  // every 2 cm up, is 5 mm from the start: its samples lie nearer the start than the floor's. The
  // start took the face, and a crowd stood on a grid up it, six of nine left out; now on the floor
  // and the box's top.
  const double s = 0.04;
  const RawSamples ground = FloorWithBlock(s, 75, 150, 2, 3, 0.25, 12, true);
  Terrain t = LoadTerrain(ground, s);
  const Character c = LoadShipped("quadruped");
  GenerateOptions o;
  o.has_start = true;
  o.start = {1.48, 0.01, 1.995};
  o.heading = {0, 0, -1};
  o.crowd = 9;
  o.crowd_spacing = 0.7;
  o.steps = 2;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK_THAT(w.stopped, !Catch::Contains("left out"));
  size_t feet = 0;
  for (const WalkTrack& track : w.tracks) {
    if (track.kind != TrackKind::kFoot) continue;
    ++feet;
    CHECK(track.keys.front().normal == Vec3{0, 1, 0});  // on the floor or the box's top
  }
  CHECK(feet == 9 * c.feet.size());
}

TEST_CASE("The default start is the sample nearest the top centre of the bounds",
          "[steps][generator]") {
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(100, 0.05, 2), 0.05);
  GenerateOptions o;
  o.steps = 2;
  const Walk w = Generate(t, c, o);
  const WalkKey& b = Body(w).keys.front();
  CHECK(b.position.x == Approx(2.475).margin(0.05));
  CHECK(b.position.z == Approx(2.475).margin(0.05));
  CHECK(b.position.y == Approx(2 + c.body_height));
}

namespace {

// A floor (y = 0, `n` x `n` samples) with a cone of 70-degree sides standing on its centre, base
// radius `radius`: the top centre of the bounds is the cone's tip, where no character stands.
// Without the floor, only the cone.
RawSamples FloorWithCone(int n, double spacing, double radius, bool floor) {
  const double side = (n - 1) * spacing, cx = 0.5 * side, cz = 0.5 * side;
  const double tan_side = std::tan(70 * kPi / 180), height = radius * tan_side;
  RawSamples s;
  if (floor) {
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const double x = i * spacing, z = j * spacing;
        if (std::hypot(x - cx, z - cz) < radius) continue;  // under the cone
        s.points.push_back({x, 0, z}), s.normals.push_back({0, 1, 0});
      }
    }
  }
  // Rings up the cone's side, samples about `spacing` apart along and around it.
  const double along = spacing * std::sin(70 * kPi / 180);
  for (double y = 0; y <= height; y += along) {
    const double r = (height - y) / tan_side;
    const int around = std::max(1, static_cast<int>(2 * kPi * r / spacing));
    for (int k = 0; k < around; ++k) {
      const double a = 2 * kPi * k / around;
      const Vec3 n{std::cos(a) * std::sin(70 * kPi / 180), std::cos(70 * kPi / 180),
                   std::sin(a) * std::sin(70 * kPi / 180)};
      s.points.push_back({cx + r * std::cos(a), y, cz + r * std::sin(a)}), s.normals.push_back(n);
    }
  }
  return s;
}

}  // namespace

TEST_CASE("A start where the character cannot stand moves to the nearest place where it can",
          "[steps][generator]") {
  // The characters that cannot stand on the cone's sides: upright ones (those aligned to the
  // terrain's normal stand on one side of it, their up along its normal).
  int tested = 0;
  for (const std::string& name : ShippedCharacters()) {
    INFO(name);
    const Character c = LoadShipped(name);
    if (c.align_to_normal || c.max_slope_deg >= 70) continue;
    ++tested;
    const double spacing = 0.15 * c.step_length, radius = 2 * c.step_length;
    const int n = static_cast<int>(8 * radius / spacing);
    Terrain t = LoadTerrain(FloorWithCone(n, spacing, radius, true), spacing);
    const double centre = 0.5 * (n - 1) * spacing;
    GenerateOptions o;
    o.steps = 2;
    // The default start: the cone's tip, which moves down to the floor beside the cone.
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CHECK(w.stopped.find("cannot stand") == std::string::npos);
    const WalkKey& b = Body(w).keys.front();
    CHECK(b.position.y == Approx(c.body_height).margin(1e-9));
    for (const WalkTrack& tr : w.tracks)
      if (tr.kind == TrackKind::kFoot) CHECK(tr.keys.front().position.y == Approx(0).margin(1e-6));
    // The nearest such place: the candidates lie at the tip's height, and snap to the floor
    // from radius / cos(70 deg) out (nearer, to the cone's side); the start lies within a
    // grid cell and a foot's spread of there.
    const double off = std::hypot(b.position.x - centre, b.position.z - centre);
    double spread = 0;
    for (const FootSpec& f : c.feet) spread = std::max(spread, Length(f.rest));
    CHECK(off > radius);
    CHECK(off < radius / std::cos(70 * kPi / 180) + spread + c.step_length);

    // A start given on the tip stands there, and the walk stops at once saying why...
    o.has_start = true;
    o.start = {centre, 10 * radius, centre};
    const Walk given = Generate(t, c, o);
    CHECK_THAT(given.stopped, Catch::Contains("step 1: foot") && Catch::Contains("cannot stand"));
    // ... unless it may move: then as the default start.
    o.start_may_move = true;
    const Walk moved = Generate(t, c, o);
    CHECK(moved.stopped.find("cannot stand") == std::string::npos);
    CHECK(Body(moved).keys.front().position.y == Approx(c.body_height).margin(1e-9));

    // Nowhere to stand (the cone alone): the walk stops at its tip, as before.
    Terrain cone = LoadTerrain(FloorWithCone(n, spacing, radius, false), spacing);
    const Walk nowhere = Generate(cone, c, GenerateOptions{});
    CHECK_THAT(nowhere.stopped, Catch::Contains("step 1: foot") && Catch::Contains("cannot stand"));
  }
  CHECK(tested >= 1);
}

TEST_CASE("A generate request's start heading up and steps are named by its fields",
          "[steps][generator]") {
  // The C ABI's request: its set-up errors named the command line's flags, which a plugin has
  // not got.
  std::ifstream in(std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/biped.json");
  const std::string biped((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE(!biped.empty());
  Terrain t = LoadTerrain(LoadShippedTerrain("hills"), 0.25);
  const auto error_of = [&](const std::string& fields) {
    Character c;
    GenerateOptions o;
    std::string error;
    REQUIRE(ParseGenerateRequest("{\"character\": " + biped + ", " + fields + "}", &c, &o,
                                 &error) == Status::kOk);
    Walk w;
    CHECK(GenerateWalk(*t.session, t.handle, c, o, &w, &error) == Status::kInvalidArgument);
    return error;
  };
  CHECK(error_of("\"heading\": [0, 1, 0]")
            .find("give a heading along the ground (request: 'heading')") != std::string::npos);
  CHECK(error_of("\"heading\": [0, 0, 0]") ==
        "request: 'heading' must be a non-zero finite vector");
  CHECK(error_of("\"up\": [0, 0, 0]") == "request: 'up' must be a non-zero finite vector");
  {  // a start beyond the queries' reach is refused as the request is read
    Character c;
    GenerateOptions o;
    std::string error;
    CHECK(ParseGenerateRequest("{\"character\": " + biped + ", \"start\": [1e300, 0, 0]}", &c, &o,
                               &error) == Status::kParseError);
    CHECK_THAT(error, Catch::StartsWith("request: 'start' is too far from the terrain to snap "
                                        "(queries reach 1e15 from it)"));
  }
  // A path walk short of its goal after the steps asked names the request's 'steps' (it said
  // "--steps").
  Character c;
  GenerateOptions request;
  std::string error;
  REQUIRE(ParseGenerateRequest("{\"character\": " + biped +
                                   ", \"start\": [20, 0, 10], \"path\": [[20, 0, 30]], "
                                   "\"steps\": 3}",
                               &c, &request, &error) == Status::kOk);
  Walk w;
  REQUIRE(GenerateWalk(*t.session, t.handle, c, request, &w, &error) == Status::kOk);
  REQUIRE(w.notes.size() == 1);
  CHECK_THAT(w.notes[0], Catch::EndsWith("(without a step count, request: 'steps', a path walk "
                                         "goes on to its goal, up to 10000 steps)"));
  // The command line's options name its flags.
  GenerateOptions o;
  CHECK(o.names.heading == "--heading");
  CHECK(o.names.up == "--up");
  CHECK(o.names.start == "--start");
  CHECK(o.names.steps == "--steps");
}

TEST_CASE("A step_height that lifts mid keys out of reach is said in the walk's notes",
          "[steps][generator]") {
  // A hexapod given step_height 0.4 with its reach of 0.3 keyed every mid key about 0.4 from
  // its body without a word.
  Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeFlat(101, 0.01, 0), 0.01);
  GenerateOptions o = StartOptions({0.5, 0, 0.3}, 4);
  const Walk usual = Generate(t, c, o);
  CHECK(usual.notes.empty());
  c.step_height = 0.4;
  const Walk high = Generate(t, c, o);
  REQUIRE(high.notes.size() == 1);
  CHECK_THAT(high.notes[0], Catch::StartsWith("step_height 0.4 lifts the feet's mid keys about "
                                              "0.39") &&
                                Catch::EndsWith(" from the body on level ground, beyond reach 0.3 "
                                                "(they are keyed there all the same: lower "
                                                "step_height or raise reach)"));
  // And so they are: a mid key farther than reach from the body's keys either side of it.
  double farthest = 0;
  const WalkTrack* body = nullptr;
  for (const WalkTrack& track : high.tracks)
    if (track.kind == TrackKind::kBody) body = &track;
  REQUIRE(body != nullptr);
  for (const WalkTrack& track : high.tracks) {
    if (track.kind != TrackKind::kFoot) continue;
    for (const WalkKey& key : track.keys) {
      if (key.phase != KeyPhase::kMid) continue;
      double nearest = 1e300;
      for (const WalkKey& b : body->keys)
        if (std::fabs(b.frame - key.frame) <= c.frames_per_step)
          nearest = std::min(nearest, Distance(b.position, key.position));
      farthest = std::max(farthest, nearest);
    }
  }
  CHECK(farthest > c.reach);
}

TEST_CASE("Feet resting nearer each other than the samples are said in the walk's notes",
          "[steps][generator]") {
  // Rests 2 mm apart (or 1e-12: only equal ones are refused) planted both feet on one sample
  // and walked them in single file without a word.
  Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(101, 0.05, 0), 0.05);
  const GenerateOptions o = StartOptions({2.5, 0, 1}, 4);
  for (const double apart : {0.002, 1e-12}) {
    INFO(apart);
    c.feet[1].rest = c.feet[0].rest + Vec3{apart, 0, 0};
    const Walk w = Generate(t, c, o);
    REQUIRE_FALSE(w.notes.empty());
    CHECK_THAT(w.notes[0],
               Catch::StartsWith("feet L and R rest only ") &&
                   Catch::EndsWith(" apart, under a tenth of reach 1.2: they may plant on the "
                                   "same samples and walk in single file (spread their rest "
                                   "positions)"));
  }
  c.feet[1].rest = c.feet[0].rest + Vec3{0.13, 0, 0};
  CHECK(Generate(t, c, o).notes.empty());
}

TEST_CASE("Rests written Z-up are said in the walk's notes", "[steps][generator]") {
  // A quadruped's rests written [x, forward, 0]: its front and hind feet started 0.1 apart
  // instead of 0.7, without a word.
  Character c = LoadShipped("quadruped");
  for (FootSpec& f : c.feet) f.rest = {f.rest.x, f.rest.z, 0};
  c.reach = 1;
  Terrain t = LoadTerrain(MakeFlat(101, 0.05, 0), 0.05);
  const Walk w = Generate(t, c, StartOptions({2.5, 0, 1}, 4));
  REQUIRE_FALSE(w.notes.empty());
  CHECK_THAT(w.notes[0], Catch::Contains(" along the up (rest y), against at most ") &&
                             Catch::EndsWith("rests are [side, up, forward], y along the up (as "
                                             "in Maya); a rig written Z-up as [x, forward, 0] "
                                             "puts its forward offsets along the up"));
}

TEST_CASE("A start given farther than a step from the terrain is said in the walk's notes",
          "[steps][generator]") {
  // A start 5 m past a floor's edge, or high above a slope, was snapped to the nearest sample
  // without a word: the character walked somewhere else than asked. Straight above or below the
  // ground (a start at y = 0 over hills) it is the ground there, as expected: nothing said.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(101, 0.05, 0), 0.05);  // 5 x 5 m at y = 0
  GenerateOptions o = StartOptions({10, 0, 2.5}, 2);      // past the edge at x = 5
  Walk w = Generate(t, c, o);
  REQUIRE(w.notes.size() == 1);
  CHECK(w.notes[0] ==
        "the start (10.0000, 0.0000, 2.5000) (--start) snaps to the terrain's sample nearest it, "
        "(5.0000, 0.0000, 2.5000), 5 away across the up (more than a step, 0.7): the character "
        "starts there");
  CheckWalk(t, c, o, w);
  o.crowd = 4;
  o.heading = {-1, 0, 0};
  o.names.start = "scene.json: characters[0]: 'start'";
  w = Generate(t, c, o);
  REQUIRE_FALSE(w.notes.empty());
  CHECK_THAT(w.notes[0],
             Catch::StartsWith("the start (10.0000, 0.0000, 2.5000) (scene.json: characters[0]: "
                               "'start') snaps to the terrain's sample nearest it"));
  CHECK(std::count_if(w.notes.begin(), w.notes.end(), [](const std::string& n) {
          return n.find("snaps to the terrain") != std::string::npos;
        }) == 1);  // once for the crowd
  // Within a step of it, or straight above it: nothing to say.
  for (const Vec3& start : {Vec3{5.6, 0, 2.5}, Vec3{2.5, 3, 2.5}, Vec3{2.5, -30, 2.5}}) {
    INFO(start.x << " " << start.y);
    CHECK(Generate(t, c, StartOptions(start, 2)).notes.empty());
  }
  // An insect beside a wall (a floor stood on its side) stands on it, its up the wall's normal.
  RawSamples wall;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 100; ++j) wall.push_back({0, 0.02 * i, 0.02 * j}, {1, 0, 0});
  Terrain side = LoadTerrain(wall, 0.02);
  o = StartOptions({3, 1, 1}, 2);
  o.heading = {0, 1, 0};
  CHECK(Generate(side, LoadShipped("hexapod"), o).notes.empty());
  o.start = {3, 1, 5};
  w = Generate(side, LoadShipped("hexapod"), o);
  REQUIRE(w.notes.size() == 1);
  CHECK_THAT(w.notes[0], Catch::Contains("(0.0000, 1.0000, 2.0000), 3 away across the up"));
}

TEST_CASE("A step_length longer than the reach allows is said once in the walk's notes",
          "[steps][generator]") {
  // Every step was shortened to keep the feet within reach (7), without a word: a biped of
  // step_length 5 and reach 1.2 took steps of under 3.
  Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(301, 0.1, 0), 0.1);  // 30 x 30 m
  GenerateOptions o = StartOptions({15, 0, 5}, 8);
  o.crowd = 2;
  CHECK(Generate(t, c, o).notes.empty());  // the shipped biped walks full steps
  c.step_length = 5;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  REQUIRE(w.notes.size() == 1);
  CHECK(
      w.notes[0] ==
      "step_length 5 is longer than reach 1.2 lets a foot travel (about 2.89 on level ground, for "
      "the foot with the least room): "
      "every step is shortened to keep the feet within reach of the body (raise reach or lower "
      "step_length)");
  CheckWalk(t, c, o, w);
  // The steps taken are no longer than that, and far longer than the shipped biped's.
  const WalkTrack& foot = *TracksOf(w, "c1")[0];
  std::vector<Vec3> ends;
  for (const WalkKey& k : foot.keys)
    if (k.phase == KeyPhase::kEnd) ends.push_back(k.position);
  REQUIRE(ends.size() >= 4);
  for (size_t i = 2; i < ends.size(); ++i) {
    CHECK(Distance(ends[i], ends[i - 1]) <= 2.9);
    CHECK(Distance(ends[i], ends[i - 1]) > 2);
  }
  // Far longer steps are shortened as well, however long (past about 60, eight shortenings by
  // a quarter fell short of the reach, and the walk stopped at step 1; 64 did past 1e8).
  for (const double step : {100.0, 1e6, 1e9}) {
    INFO("step_length " << step);
    c.step_length = step;
    const Walk far = Generate(t, c, o);
    INFO(far.stopped);
    CHECK(far.stopped.empty());
    CHECK(far.notes.size() == 1);
    CheckWalk(t, c, o, far);
  }
  // Every shipped character walks its full step_length: no note.
  for (const std::string& name : ShippedCharacters()) {
    INFO(name);
    CHECK(CheckedWalkOnFlat(LoadShipped(name), 6).notes.empty());
  }
}

TEST_CASE("A reach that leaves little room walks on level ground, shorter as it tightens",
          "[steps][generator]") {
  // A trotting quadruped whose reach leaves its feet a few centimetres of travel: each step's
  // own reach check counted only that foot's share of the body's move, so a hind foot's long
  // step carried the body away from the other hind foot; every group waited on another, and
  // the walk stopped at step 2 without a foot moving (at reach 0.60 and 0.61, not 0.62).
  Character c = LoadShipped("quadruped");
  Terrain t = LoadTerrain(MakeFlat(321, 0.025, 0), 0.025);  // 8 x 8 m
  const GenerateOptions o = StartOptions({4, 0, 4}, 20);
  double previous = 0;
  for (const double reach : {0.6, 0.61, 0.62, 0.65}) {
    INFO("reach " << reach);
    c.reach = reach;
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CHECK(w.stopped.empty());
    CheckWalk(t, c, o, w);
    const WalkTrack& body = *TracksOf(w, "").back();
    REQUIRE(body.kind == TrackKind::kBody);
    const double travelled = Distance(body.keys.back().position, body.keys.front().position);
    CHECK(travelled > 0.2);
    CHECK(travelled >= previous);  // more room, farther
    previous = travelled;
  }
}

TEST_CASE("A group's steps are held within reach together, at full length where they fit",
          "[steps][generator]") {
  // Each step was held within reach of the body moved by its own share of the step alone: the
  // other feet of its group move the body too, so steps were cut that fit whole (a hopping
  // quadruped's front feet hopped 0.3 of 0.4 every fourth hop; a trot at step_length 0.6 took
  // 0.45 every other step), and a biped near its limit, cut by a quarter at its first step,
  // walked a third short all the way.
  Terrain t = LoadTerrain(MakeFlat(601, 0.05, 0), 0.05);  // 30 x 30 m
  const GenerateOptions o = StartOptions({15, 0, 5}, 16);
  // The foot travel of each step after the first two of every foot, and the walk's notes.
  auto steps = [&](const Character& c, std::vector<double>* lengths) {
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CHECK(w.stopped.empty());
    CheckWalk(t, c, o, w);
    lengths->clear();
    for (const WalkTrack& track : w.tracks) {
      if (track.kind != TrackKind::kFoot) continue;
      std::vector<Vec3> ends;
      for (const WalkKey& k : track.keys)
        if (k.phase == KeyPhase::kEnd) ends.push_back(k.position);
      for (size_t i = 3; i < ends.size(); ++i) lengths->push_back(Distance(ends[i], ends[i - 1]));
    }
    REQUIRE(lengths->size() >= 8);
    return w.notes;
  };
  std::vector<double> lengths;
  Character hopper = LoadShipped("quadruped");
  hopper.gait = {{0, 1, 2, 3}};
  steps(hopper, &lengths);
  for (const double l : lengths) CHECK(l == Approx(hopper.step_length).margin(0.051));
  Character trot = LoadShipped("quadruped");
  trot.step_length = 0.6;
  CHECK(steps(trot, &lengths).empty());  // within what reach lets a foot travel
  for (const double l : lengths) CHECK(l == Approx(0.6).margin(0.051));
  Character biped = LoadShipped("biped");
  biped.step_length = 2.8;  // reach 1.2 lets a foot travel about 2.89
  steps(biped, &lengths);
  for (const double l : lengths) CHECK(l > 2.6);
}

TEST_CASE("A stop for reach says when the feet's room is narrower than the samples' spacing",
          "[steps][generator]") {
  // A hexapod with 1 cm of room within reach on a 2.5 cm grid: no sample lay within its room,
  // and the walk stopped at its first step saying only "beyond reach".
  Character c = LoadShipped("hexapod");
  double rest = 0;
  for (const FootSpec& f : c.feet)
    rest = std::max(rest, std::hypot(f.rest.x, c.body_height - f.rest.y, f.rest.z));
  c.reach = rest + 0.012;
  Terrain t = LoadTerrain(MakeFlat(161, 0.025, 0), 0.025);  // 4 x 4 m
  const Walk w = Generate(t, c, StartOptions({2, 0, 1}, 30));
  REQUIRE_FALSE(w.stopped.empty());
  CHECK_THAT(w.stopped, Catch::Contains("beyond reach") &&
                            Catch::Contains("of room within it, less than the terrain's samples "
                                            "lie apart (about 0.025") &&
                            Catch::Contains("raise reach, or resample the terrain finer"));
}

TEST_CASE("A slope_step_scale far below 1 still climbs a slope", "[steps][generator]") {
  // A step under 2% of step_length was a step in place: with slope_step_scale 0.019 every step
  // up a ramp past the threshold was one, and the walk a dead end at the ramp's foot.
  Character c = LoadShipped("biped");
  c.slope_step_scale = 0.019;
  const double spacing = 0.005;
  Terrain t = LoadTerrain(MakeRamp(160, 300, spacing, 25), spacing);
  GenerateOptions o = StartOptions({0.4, 0.1 * std::sin(25 * 3.14159265358979 / 180),
                                    0.1 * std::cos(25 * 3.14159265358979 / 180)},
                                   40);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
}

TEST_CASE("GenerateWalk takes a null error string", "[steps][generator]") {
  // Bad options with no error string to fill dereferenced it (a crash).
  Terrain t = LoadTerrain(MakeFlat(41, 0.25, 0), 0.25);
  GenerateOptions o;
  o.up = {0, 0, 0};
  Walk w;
  CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("biped"), o, &w, nullptr) ==
        Status::kInvalidArgument);
}

TEST_CASE("A multiped whose rest lies against a riser starts on a tread", "[steps][generator]") {
  // A quadruped started mid-tread at 45 degrees to the treads has a front foot's rest (going up)
  // or a hind foot's (going down) against a riser: the foot snapped onto the riser, leaning 90
  // degrees from the start's up, and the walk stopped at once (8 of 24 walks on these stairs).
  // As an upright character's, such a foot snaps again from its rest moved out along the face.
  const Character quadruped = LoadShipped("quadruped");
  const double cos_max_slope = std::cos(quadruped.max_slope_deg * 3.14159265358979 / 180);
  const int treads = 20;
  for (const double rise : {0.05, 0.1, 0.2}) {
    for (const double run : {0.25, 0.4}) {
      Terrain t = LoadTerrain(MakeStairs(treads, rise, run, 6, 0.03), 0.03);
      for (const bool up : {true, false}) {
        const int from = up ? 1 : treads - 2;
        GenerateOptions o = StartOptions({3, from * rise, (from + 0.5) * run}, 6);
        o.heading = Normalize(Vec3{1, 0, up ? 1.0 : -1.0});
        const Walk w = Generate(t, quadruped, o);
        INFO(rise << " x " << run << (up ? " up: " : " down: ") << w.stopped);
        CheckWalk(t, quadruped, o, w);
        CHECK(w.stopped.find("step 1:") == std::string::npos);
        for (const WalkTrack& track : w.tracks) {
          if (track.kind != TrackKind::kFoot) continue;
          REQUIRE_FALSE(track.keys.empty());
          INFO(track.name);
          CHECK(track.keys.front().normal.y >= cos_max_slope);
        }
      }
    }
  }
}
