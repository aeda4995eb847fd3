// The step generator on generated terrain, for every shipped character: ramps and slopes,
// stairs, a sphere, walls and ceilings, slabs and roofs, a cliff. Every walk is checked against
// the invariants of walk_checks.h.
#include <unistd.h>

#include <algorithm>
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

TEST_CASE("Walks up and down a 20-degree ramp", "[steps][generator]") {
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double s = Scale(c), spacing = 0.05 * s, width = 8 * c.reach;
    const double slope = 20 * kPi / 180;
    const int nx = static_cast<int>(width / spacing),
              nz = static_cast<int>((14 * c.step_length + 6 * c.reach) / spacing);
    Terrain t = LoadTerrain(MakeRamp(nx, nz, spacing, 20), spacing);
    const double length = nz * spacing;
    for (bool uphill : {true, false}) {
      INFO(name << (uphill ? " uphill" : " downhill"));
      const double d = uphill ? 2 * c.reach : length - 2 * c.reach;
      const double climb = 2 * c.step_length * std::sin(slope);
      WalkTwelveSteps(t, c, {width / 2, std::sin(slope) * d, std::cos(slope) * d}, uphill,
                      uphill ? climb : -climb);
    }
  }
}

TEST_CASE("A walk across a slope keeps its line and does not drift uphill", "[steps][generator]") {
  // The central locators are placed lead/2 above the ground and snapped: on ground leaning
  // across the heading they slid uphill, and a biped crossing a 25-degree slope climbed 2 m
  // over 10 m walked.
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    for (const double slope : {15.0, 25.0, 35.0}) {
      INFO(name << ", " << slope << " degrees");
      const double spacing = c.step_length / 10, rad = slope * kPi / 180;
      const int nx = static_cast<int>((20 * c.step_length + 4 * c.reach) / spacing);
      const int nz = static_cast<int>(8 * c.reach / spacing);
      Terrain t = LoadTerrain(MakeRamp(nx, nz, spacing, slope), spacing);
      const double d = nz * spacing / 2;  // along the ramp's surface
      GenerateOptions o;
      o.has_start = true;
      o.start = {2 * c.reach, std::sin(rad) * d, std::cos(rad) * d};
      o.heading = {1, 0, 0};
      o.steps = 30;
      const Walk w = Generate(t, c, o);
      INFO(w.stopped);
      REQUIRE(w.stopped.empty());
      CheckWalk(t, c, o, w);
      const Vec3 moved = Body(w).keys.back().position - Body(w).keys.front().position;
      CHECK(moved.x > 5 * c.step_length);
      CHECK(std::fabs(moved.z) < 0.03 * moved.x);
    }
  }
}

TEST_CASE("Steps are shorter on a slope past the threshold", "[steps][generator]") {
  const Character c = LoadShipped("biped");
  const double spacing = 0.05;
  auto stride = [&](double slope_deg) {
    Terrain t = LoadTerrain(MakeRamp(120, 300, spacing, slope_deg), spacing);
    GenerateOptions o;
    o.has_start = true;
    o.start = {3, std::sin(slope_deg * kPi / 180) * 2, std::cos(slope_deg * kPi / 180) * 2};
    o.steps = 10;
    const Walk w = Generate(t, c, o);
    REQUIRE(w.stopped.empty());
    CheckWalk(t, c, o, w);
    // The longest foot travel over the last 4 steps.
    double longest = 0;
    for (const WalkTrack& tr : w.tracks) {
      if (tr.kind != TrackKind::kFoot) continue;
      for (size_t i = tr.keys.size() > 6 ? tr.keys.size() - 6 : 0; i + 2 < tr.keys.size(); ++i)
        if (tr.keys[i].phase == KeyPhase::kStart)
          longest = std::max(longest, Distance(tr.keys[i].position, tr.keys[i + 2].position));
    }
    return longest;
  };
  const double flat = stride(0), steep = stride(25);
  CHECK(flat > 0.9 * c.step_length);
  CHECK(flat <= c.step_length + 1e-6);
  CHECK(steep <= c.slope_step_scale * c.step_length + 2 * spacing);
  CHECK(steep < 0.8 * flat);
}

TEST_CASE("Walks up and down stairs", "[steps][generator]") {
  // Down, every foot reaches past a nose: a biped onto the tread below; a quadruped aims down
  // when its target hangs over the nose; insects wrap over the nose onto the riser, then down.
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double s = Scale(c);
    const double rise = 0.15 * s, run = 0.35 * s;
    const int steps = 24;
    const double spacing = 0.025 * s;
    Terrain t = LoadTerrain(MakeStairs(steps, rise, run, 8 * c.reach, spacing), spacing);
    auto depth = [&](const Vec3& p) { return FlightDepth(p, steps, rise, run, 0); };
    INFO(name << " up");
    CHECK(DeepestSwing(WalkTwelveSteps(t, c, {4 * c.reach, 0, c.reach}, true, 3 * rise), depth) <=
          spacing);
    INFO(name << " down");
    const Vec3 top{4 * c.reach, rise * (steps - 1), run * steps - c.reach};
    CHECK(DeepestSwing(WalkTwelveSteps(t, c, top, false, -2 * rise), depth) <= spacing);
  }
}

TEST_CASE("A biped climbs risers exactly max_rise high", "[steps][generator]") {
  // Samples are stored in float: a 0.4 riser measured 0.40000001 and the biped (max_rise 0.4)
  // stopped at its foot as at a cliff.
  const Character c = LoadShipped("biped");
  REQUIRE(c.max_rise == 0.4);
  const double spacing = 0.025;
  Terrain t = LoadTerrain(MakeStairs(5, c.max_rise, 0.5, 1.5, spacing), spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {0.75, 0, 0.1};
  o.steps = 10;
  const Walk w = Generate(t, c, o);
  CheckWalk(t, c, o, w);
  double highest = 0;
  for (const WalkTrack& track : w.tracks)
    for (const WalkKey& k : track.keys)
      if (track.kind == TrackKind::kFoot && k.phase == KeyPhase::kEnd)
        highest = std::max(highest, k.position.y);
  INFO(w.stopped);
  CHECK(highest == Approx(4 * c.max_rise));  // the top tread
}

TEST_CASE("A multiped's body climbing stairs taller than itself stays out of their noses",
          "[steps][generator]") {
  // The octopod (4 cm body, reach 32 cm) up 18 cm stairs: with feet on two treads its body,
  // raised at most body_height, stayed 2.9 cm behind a riser; a body inside the terrain may
  // now rise as far as reach allows.
  for (const char* name : {"octopod", "hexapod"}) {
    const Character c = LoadShipped(name);
    const int steps = 8;
    const double rise = 0.18, run = 0.3, spacing = 0.02;
    Terrain t = LoadTerrain(MakeStairs(steps, rise, run, 1.5, spacing), spacing);
    const GenerateOptions o = StartOptions({0.75, 0, -0.6}, 60);
    const Walk w = Generate(t, c, o);
    INFO(name << ": " << w.stopped);
    CheckWalk(t, c, o, w);
    double deepest = 0;
    for (const WalkKey& k : Body(w).keys)
      deepest = std::max(deepest, FlightDepth(k.position, steps, rise, run, 0));
    CHECK(deepest == 0);
    CHECK(Body(w).keys.back().position.y > 3 * rise);
  }
}

TEST_CASE("The default start stands no foot on ground steeper than max_slope_deg",
          "[steps][generator]") {
  // The shipped quadruped on the shipped stairs, default start: its front paws stood on a
  // riser (90 degrees from up), which passed against the feet's averaged normal (two risers and
  // two treads: 45 degrees).
  Terrain t = LoadTerrain(LoadShippedTerrain("stairs"), 0.03);
  for (const std::string name : {"quadruped", "hexapod", "octopod"}) {
    const Character c = LoadShipped(name);
    INFO(name);
    GenerateOptions o;
    o.steps = 1;
    const Walk w = Generate(t, c, o);
    for (const WalkTrack& track : w.tracks) {
      if (track.kind != TrackKind::kFoot) continue;
      const WalkKey& first = track.keys.front();
      INFO(track.name << " at " << first.position.x << ", " << first.position.y << ", "
                      << first.position.z);
      CHECK(first.normal.y >= std::cos(c.max_slope_deg * M_PI / 180));  // from world up
    }
  }
}

TEST_CASE("The shipped quadruped climbs the shipped stairs, the insects walk down them",
          "[steps][generator]") {
  // data/terrain/stairs.pts: 8 steps of 0.18 x 0.3 m along +Z, 1.5 m wide, top tread at 1.26.
  // The quadruped's toes start close to each riser, so its swing lifts before it travels.
  Terrain t = LoadTerrain(LoadShippedTerrain("stairs"), 0.03);
  // Also the quadruped in a four-beat walk, hind foot first: at this start its hind feet stand
  // off the flight's back edge, their targets behind them until a front foot steps (it stopped
  // at step 1 as at a dead end).
  for (const std::string name : {"quadruped", "quadruped walk", "hexapod", "octopod"}) {
    Character c = LoadShipped(name == "quadruped walk" ? "quadruped" : name);
    if (name == "quadruped walk") c.gait = {{2}, {0}, {3}, {1}};  // LH, LF, RH, RF
    const bool up = name.rfind("quadruped", 0) == 0;
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = up ? Vec3{0.75, 0, 0.1} : Vec3{0.75, 1.26, 2.3};
    o.heading = {0, 0, up ? 1.0 : -1.0};
    o.steps = 200;  // until it walks off the far end of the flight
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CheckWalk(t, c, o, w);
    const auto& body = Body(w).keys;
    if (up) {
      CHECK(body.back().position.y > 1.26);
    } else {
      CHECK(body.back().position.y < 0.1 + c.body_height);
    }
    // Off the far end of the flight: the terrain ends there.
    CHECK_THAT(w.stopped,
               Catch::Contains("(the terrain ends, or rises as a wall at its bounds, before it)"));
  }
}

TEST_CASE("Feet off the terrain's back edge wait for the body to move on, in any gait order",
          "[steps][generator]") {
  // The octopod one foot at a time, hind feet first, starting with its hind half off the back
  // edge of flat ground: the hind feet snap onto the edge, ahead of their rests, so their
  // targets lie behind them. They stepped backwards, over the edge ("the terrain ends before
  // it", at step 1); now, finding no foothold there, they keep their place until the front
  // feet have moved the body on.
  Character c = LoadShipped("octopod");
  c.gait = {{3}, {7}, {2}, {6}, {1}, {5}, {0}, {4}};  // L4, R4, L3, R3, L2, R2, L1, R1
  const double spacing = c.step_length / 10;
  Terrain t = LoadTerrain(MakeFlat(200, spacing, 0), spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {100 * spacing, 0, -0.05};  // the ground point itself behind the edge
  o.steps = 48;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
  CHECK(Body(w).keys.back().position.z > Body(w).keys.front().position.z + 2 * c.step_length);
}

TEST_CASE("Swing arcs clear a resampled stair mesh, whose riser tops lie beside the noses",
          "[steps][generator]") {
  // Poisson-disk samples with flat normals: above a nose, the nearest sample is often the top of
  // the riser below it, facing -z, so an arc point high above the nose lies only a little in
  // front of that sample's plane. Its clearance is its distance to the sample (less the gap the
  // sampling leaves), not its height along that normal, or the arc is raised in vain. And a toe
  // often lands a few millimetres from the next riser: its arc lifts straight up, keeping half
  // the toe's own distance from the riser, not the full clearance. The quadruped's reach is
  // raised to 1 m so that reach does not stop it on stairs this steep first. Nine samplings
  // (three separations, three seeds) all climb to the top; with the height along the normal
  // alone one did, with the distance but the full clearance at the toe four did.
  Character c = LoadShipped("quadruped");
  c.reach = 1.0;
  int to_the_top = 0;
  for (const double separation : {0.025, 0.03, 0.04}) {
    for (const uint64_t seed : {1, 2, 3}) {
      RawSamples stairs;
      MeshSampleOptions mo;
      mo.separation = separation;
      mo.smooth_normals = false;
      mo.seed = seed;
      REQUIRE(SampleMesh(MakeStairsMesh(8, 0.18, 0.3, 1.5), mo, &stairs, nullptr) == Status::kOk);
      // Neighbouring samples lie at least 2/3 of the separation apart (CheckWalk's spacing:
      // no surface nearer than the distance to the nearest sample less twice that).
      Terrain t = LoadTerrain(stairs, separation * 2 / 3);
      GenerateOptions o;
      o.has_start = true;
      o.start = {0.75, 0, -0.6};
      o.steps = 30;
      const Walk w = Generate(t, c, o);
      INFO(separation << " " << seed << ": " << w.stopped);
      CheckWalk(t, c, o, w);
      auto depth = [](const Vec3& p) { return FlightDepth(p, 8, 0.18, 0.3, 0.18); };
      CHECK(DeepestSwing(w, depth) <= separation);
      to_the_top += Body(w).keys.back().position.y > 8 * 0.18;
    }
  }
  CHECK(to_the_top == 9);
}

TEST_CASE("A foot whose swing arc cannot clear takes its next foothold instead",
          "[steps][generator]") {
  // The shipped stairs with every nose sampled twice, the copy facing the riser first in the
  // file: queries answer it, so footholds at a nose are refused as too steep and footholds
  // just past one are often reached by arcs that snap to it and cannot clear. The quadruped
  // climbs anyway by taking its next, shorter or longer, foothold.
  const RawSamples lattice = LoadShippedTerrain("stairs");
  RawSamples doubled;
  for (size_t i = 0; i < lattice.size(); ++i) {
    const Vec3 p = lattice.points[i];
    const double steps = p.z / 0.3;
    if (lattice.normals[i].y == 1 && p.y > 0 && std::fabs(steps - std::round(steps)) < 1e-4)
      doubled.push_back(p, {0, 0, -1});
  }
  REQUIRE(doubled.size() > 100);
  for (size_t i = 0; i < lattice.size(); ++i)
    doubled.push_back(lattice.points[i], lattice.normals[i]);
  Terrain t = LoadTerrain(doubled, 0.03);
  const Character c = LoadShipped("quadruped");
  const GenerateOptions o = StartOptions({0.75, 0, 0.1}, 40);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CheckWalk(t, c, o, w);
  CHECK(Body(w).keys.back().position.y > 1.26);
}

TEST_CASE("Multipeds walk around a sphere, bipeds stop where it gets too steep",
          "[steps][generator]") {
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double radius = 3 * c.reach, spacing = c.step_length / 10;
    const int count = static_cast<int>(4 * kPi * radius * radius / (spacing * spacing));
    Terrain t = LoadTerrain(MakeSphere(count, {0, 0, 0}, radius), spacing);
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = {0, radius, 0};
    o.steps = static_cast<int>(1.3 * kPi * radius / (c.step_length / 2));
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CheckWalk(t, c, o, w);
    if (c.align_to_normal) {
      CHECK(w.stopped.empty());
      // Past the bottom: the body went around, its up turned upside down.
      double lowest = 0, most_down = 1;
      for (const WalkKey& k : Body(w).keys) lowest = std::min(lowest, k.position.y);
      for (const Quat& q : Body(w).rotations) most_down = std::min(most_down, BodyUp(q).y);
      CHECK(lowest < -0.8 * radius);
      CHECK(most_down < -0.8);
    } else {
      CHECK_THAT(w.stopped, Catch::Contains("step ") && Catch::Contains("max_slope_deg"));
      CHECK(StepsDone(w) > 2);
    }
  }
}

TEST_CASE("An insect inside a thin-walled pipe stands on the inner face and not the outer one",
          "[steps][generator]") {
  // A pipe of radius 0.5 m along z with a 2 cm wall, both faces sampled every ~7 mm. The rests
  // laid on the tangent plane at the start fall about 2 cm outside the curved inner face,
  // nearer the outer one: the hexapod stood on the outside, hanging upside down below the pipe,
  // its legs crossing under it.
  const Character c = LoadShipped("hexapod");
  const double inner = 0.5, wall = 0.02, spacing = 0.007, length = 1.6;
  RawSamples pipe;
  for (const double r : {inner, inner + wall}) {
    const int around = static_cast<int>(2 * kPi * r / spacing);
    const int along = static_cast<int>(length / spacing);
    for (int k = 0; k <= along; ++k)
      for (int i = 0; i < around; ++i) {
        const double a = 2 * kPi * i / around, x = std::cos(a), y = std::sin(a);
        const double facing = r == inner ? -1 : 1;  // the inner face looks at the axis
        pipe.push_back({r * x, r * y, k * spacing}, {facing * x, facing * y, 0});
      }
  }
  Terrain t = LoadTerrain(pipe, spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {0, -0.45, 0.4};  // 5 cm above the inner floor
  o.heading = {0, 0, 1};
  o.steps = 20;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  size_t on_inner = 0, keys = 0;
  for (const WalkTrack& track : w.tracks) {
    if (track.kind != TrackKind::kFoot) continue;
    for (const WalkKey& k : track.keys) {
      if (k.phase == KeyPhase::kMid) continue;
      ++keys;
      on_inner += std::fabs(std::hypot(k.position.x, k.position.y) - inner) < 1e-3;
    }
  }
  CHECK(keys > 0);
  CHECK(on_inner == keys);
  // The body inside the pipe, above its floor, its up toward the axis.
  CHECK(Body(w).keys[0].position.y > -inner);
  CHECK(BodyUp(Body(w).rotations[0]).y > 0.8);
  CheckWalk(t, c, o, w);
}

TEST_CASE("A goal off the terrain is reached across the ground whatever its height",
          "[steps][generator]") {
  // Multipeds' up leans with the ground: their goals were judged along it, so on a 15-degree
  // ramp a goal 5 m above the ground was reached a metre past it, and on a DEM 537 m up a 2D
  // path at y = 0 led nowhere (a dead end). The same goal at any height ends the walk at the
  // same place across the ground, for every character.
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double slope = 15, spacing = c.step_length / 10, rad = slope * kPi / 180;
    const int nx = static_cast<int>(10 * c.step_length / spacing);
    const int nz = static_cast<int>((14 * c.step_length + 6 * c.reach) / spacing);
    Terrain t = LoadTerrain(MakeRamp(nx, nz, spacing, slope), spacing);
    const double d0 = 2 * c.reach, d1 = d0 + 8 * c.step_length;
    const double x = nx * spacing / 2, z1 = std::cos(rad) * d1, ground = std::sin(rad) * d1;
    for (const double height : {0.1 * c.step_length + 5 * c.reach, 500.0, -ground - 500}) {
      INFO(name << ", goal " << height << " above the ground");
      GenerateOptions o;
      o.has_start = true;
      o.start = {x, std::sin(rad) * d0, std::cos(rad) * d0};
      const Vec3 goal{x + 2 * c.step_length, ground + height, z1};
      o.path.push_back(goal);
      const Walk w = Generate(t, c, o);
      INFO(w.stopped);
      REQUIRE(w.stopped.empty());
      CheckWalk(t, c, o, w);
      Vec3 centroid;
      int feet = 0;
      for (const WalkTrack& tr : w.tracks) {
        if (tr.kind != TrackKind::kFoot) continue;
        centroid += tr.keys.back().position, ++feet;
      }
      centroid = centroid / static_cast<double>(feet);
      const double across = std::hypot(centroid.x - goal.x, centroid.z - goal.z);
      CHECK(across <= 0.5 * c.step_length / std::cos(rad) + 1e-9);
    }
  }
}

TEST_CASE("A trotting quadruped's body does not rock from side to side over curved ground",
          "[steps][generator]") {
  // The plane fitted to a diagonal gait's feet leans one way after one pair steps and the
  // other way after the next on curved ground: down a sphere the body rolled 8 to 10 degrees
  // each step, the other way each time. The body's up is the fit over the gait's cycle.
  const Character c = LoadShipped("quadruped");
  const double radius = 3, spacing = 0.04;
  const int count = static_cast<int>(4 * kPi * radius * radius / (spacing * spacing));
  Terrain t = LoadTerrain(MakeSphere(count, {0, 0, 0}, radius), spacing);
  const GenerateOptions o = StartOptions({0, 2 * radius, 0}, 30);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CheckWalk(t, c, o, w);
  const auto& turns = Body(w).rotations;
  REQUIRE(turns.size() > 20);
  int flips = 0;
  double most = 0, before = 0;
  for (size_t i = 1; i < turns.size(); ++i) {
    // The roll from one key to the next: the new up along the old left.
    const Vec3 left = Rotate(turns[i - 1], {1, 0, 0});
    const double roll = std::asin(std::clamp(Dot(BodyUp(turns[i]), left), -1.0, 1.0)) * 180 / kPi;
    most = std::max(most, std::fabs(roll));
    if (std::fabs(roll) > 1.5 && std::fabs(before) > 1.5 && roll * before < 0) ++flips;
    before = roll;
  }
  INFO(flips << " rolls the other way from the key before; the largest " << most << " deg");
  CHECK(flips <= 2);
  CHECK(most < 5);
}

TEST_CASE("A goal on the far side of a sphere is walked to, not reached where the walk starts",
          "[steps][generator]") {
  // A hexapod on top of a sphere given the bottom as its goal made no step: the goal lay within
  // half a step along its ground, straight below it.
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    if (!c.align_to_normal) continue;
    const double radius = 3 * c.reach, spacing = c.step_length / 10;
    const int count = static_cast<int>(4 * kPi * radius * radius / (spacing * spacing));
    Terrain t = LoadTerrain(MakeSphere(count, {0, 0, 0}, radius), spacing);
    for (const Vec3& goal : {Vec3{0, -radius, 0}, Vec3{0, -radius, 0.02 * radius}}) {
      INFO(name << ", goal " << goal.x << ", " << goal.y << ", " << goal.z);
      GenerateOptions o;
      o.has_start = true;
      o.start = {0, radius, 0};
      o.path = {goal};
      const Walk w = Generate(t, c, o);
      INFO(w.stopped);
      REQUIRE(w.stopped.empty());
      CheckWalk(t, c, o, w);
      CHECK(StepsDone(w) > 10);
      Vec3 centroid;
      int feet = 0;
      for (const WalkTrack& tr : w.tracks)
        if (tr.kind == TrackKind::kFoot) centroid += tr.keys.back().position, ++feet;
      CHECK(Distance(centroid / static_cast<double>(feet), goal) < c.step_length);
    }
  }
}

TEST_CASE("A goal on the floor under the table top a biped stands on is not reached there",
          "[steps][generator]") {
  // The goal lies straight below, 0.9 m down, with no way down: the walk stops saying so.
  const Character c = LoadShipped("biped");
  RawSamples s = MakeFlat(120, 0.05, 0);
  for (int k = 0; k <= 40; ++k)
    for (int i = 0; i <= 40; ++i) s.push_back({2 + i * 0.05, 0.9, 2 + k * 0.05}, {0, 1, 0});
  Terrain t = LoadTerrain(s, 0.05);
  GenerateOptions o;
  o.has_start = true;
  o.start = {3, 1, 3};
  o.path = {{3.1, 0, 3}};
  const Walk w = Generate(t, c, o);
  CHECK(StepsDone(w) > 0);
  CHECK_THAT(w.stopped, Catch::Contains("no way to the path's goal (3.1000, 0.0000, 3.0000): "
                                        "the body has come no nearer to it than"));
  CheckWalk(t, c, o, w);
}

TEST_CASE("A stop shows the value that broke a limit, never rounded onto the limit",
          "[steps][generator]") {
  // Flat ground up to z = 0, then a 20-degree ramp; the biped allows 19.99999 degrees.
  Character c = LoadShipped("biped");
  c.max_slope_deg = 19.99999;
  const double spacing = 0.05;
  RawSamples ground = MakeFlat(160, spacing, 0);
  for (Vec3& p : ground.points) p.z -= 160 * spacing;
  const RawSamples ramp = MakeRamp(160, 160, spacing, 20);
  ground.points.insert(ground.points.end(), ramp.points.begin(), ramp.points.end());
  ground.normals.insert(ground.normals.end(), ramp.normals.begin(), ramp.normals.end());
  Terrain t = LoadTerrain(ground, spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {4, 0, -3};
  o.steps = 20;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  const size_t leans = w.stopped.find(" leans "), limit = w.stopped.find("max_slope_deg ");
  REQUIRE(leans != std::string::npos);
  REQUIRE(limit != std::string::npos);
  const double shown = std::stod(w.stopped.substr(leans + 7));
  const double shown_limit = std::stod(w.stopped.substr(limit + 14));
  CHECK(shown_limit == c.max_slope_deg);
  CHECK(shown > shown_limit);
}

namespace {

// A floor sampled every 4 cm (x to 3 m, z to 6 m) and a slab from y = lo to hi over z from 2 to
// 4 m, its faces on the same lattice; with `underside` false, only its top (a roof modelled as
// one face, facing up). [Units: wu]
RawSamples FloorAndSlab(double lo, double hi, bool underside) {
  const double s = 0.04;
  RawSamples out;
  for (int i = 0; i <= 75; ++i) {
    const double x = i * s;
    for (int k = 0; k <= 150; ++k) {
      const double z = k * s;
      out.push_back({x, 0, z}, {0, 1, 0});
      if (z < 2 - 1e-9 || z > 4 + 1e-9) continue;
      out.push_back({x, hi, z}, {0, 1, 0});
      if (underside) out.push_back({x, lo, z}, {0, -1, 0});
    }
    for (double y = lo + s / 2; underside && y < hi; y += s) {
      out.push_back({x, y, 2}, {0, 0, -1});
      out.push_back({x, y, 4}, {0, 0, 1});
    }
  }
  return out;
}

// The deepest any straight line from a body key to the feet (where they stand at its frame)
// passes into the box z in (2, 4), y in (lo, hi).
double DeepestLeg(const Walk& w, double lo, double hi) {
  double deepest = 0;
  for (const WalkTrack& body : w.tracks) {
    if (body.kind != TrackKind::kBody) continue;
    for (const WalkKey& b : body.keys) {
      for (const WalkTrack& foot : w.tracks) {
        if (foot.kind != TrackKind::kFoot || foot.character != body.character) continue;
        Vec3 at = foot.keys.front().position;
        for (const WalkKey& k : foot.keys)
          if (k.frame <= b.frame) at = k.position;
        for (int j = 1; j < 200; ++j) {
          const Vec3 p = Lerp(at, b.position, j / 200.0);
          if (p.z > 2 && p.z < 4 && p.y > lo && p.y < hi)
            deepest = std::max(deepest, std::min({p.z - 2, 4 - p.z, p.y - lo, hi - p.y}));
        }
      }
    }
  }
  return deepest;
}

}  // namespace

TEST_CASE("An upright body stops before a slab lower than it, its legs never through the slab",
          "[steps][generator]") {
  // A floor and a slab 10 cm thick 0.6 m up, or 2 cm thick 0.65 m up (thinner than the spine's
  // check points lie apart), over z from 2 to 4 m: a biped (body 0.95 m up) walked on under it,
  // feet on the floor and body over the slab, its legs through the slab for 7 steps. Now the
  // walk stops at the first step whose body has no room, with the keys before it (CheckWalk:
  // every foot ends planted by the body's last key); each body key's straight lines to the
  // feet stay out of the slab.
  const Character c = LoadShipped("biped");
  // A slab 0.3 to 0.44 m up lies below the spine's lowest point checked (half the body's
  // height): its plane crosses the spine lower down (a first version of the crossing rule
  // missed it, the legs through it).
  for (const auto& [lo, hi] : {std::pair{0.6, 0.7}, std::pair{0.65, 0.67}, std::pair{0.3, 0.44}}) {
    Terrain t = LoadTerrain(FloorAndSlab(lo, hi, true), 0.04);
    GenerateOptions o;
    o.has_start = true;
    o.start = {1.5, 0, 0.5};
    o.steps = 16;
    const Walk w = Generate(t, c, o);
    INFO(lo << " to " << hi << ": " << w.stopped);
    CheckWalk(t, c, o, w);
    CHECK_THAT(w.stopped, Catch::Contains("no room for the body"));
    CHECK(StepsDone(w) >= 2);
    CHECK(DeepestLeg(w, lo, hi) == 0);
  }
}

TEST_CASE("A biped climbs stairs steeper than its stride, a tread every two steps",
          "[steps][generator]") {
  // Risers of 26 to 32 cm on treads of 20 to 26 cm: the central locator, placed half a step
  // ahead and lead/2 up, snapped onto the riser of the tread after next (out of max_rise's
  // reach), and the feet shuffled along each tread (four steps a tread), or the start stopped
  // with "no room for the body". It now lands on the tread before that riser: each foot climbs
  // one tread a step.
  const Character c = LoadShipped("biped");
  const int treads = 8;
  const double spacing = 0.03;
  for (const auto& [rise, run] : std::vector<std::pair<double, double>>{
           {0.3, 0.25}, {0.32, 0.2}, {0.28, 0.24}, {0.26, 0.26}}) {
    Terrain t = LoadTerrain(MakeStairs(treads, rise, run, 2, spacing), spacing);
    GenerateOptions o = StartOptions({1, 0, 0.1}, 2 * (treads - 1) + 2);
    o.heading = {0, 0, 1};
    const Walk w = Generate(t, c, o);
    INFO(rise << " x " << run << ": " << w.stopped);
    CheckWalk(t, c, o, w);
    CHECK_THAT(w.stopped, !Catch::Contains("no room"));
    double highest = 0;
    for (const WalkTrack& track : w.tracks)
      for (const WalkKey& k : track.keys)
        if (track.kind == TrackKind::kFoot && k.phase == KeyPhase::kEnd)
          highest = std::max(highest, k.position.y);
    CHECK(highest == Approx((treads - 1) * rise));  // the top tread
  }
}

TEST_CASE("A biped climbs steep stairs without taking the next nose for an overhang",
          "[steps][generator]") {
  // 19 cm risers, 26 cm treads, sampled every 3 cm: with both feet on a tread just before its
  // riser, the next nose lies two spacings ahead of the spine, and its plane crossed the spine
  // within the gap: every start stopped with "no room for the body" halfway up.
  const Character c = LoadShipped("biped");
  const int steps = 20;
  const double rise = 0.19, run = 0.26, spacing = 0.03;
  Terrain t = LoadTerrain(MakeStairs(steps, rise, run, 2, spacing), spacing);
  for (const double z : {0.02, 0.11, 0.2}) {
    const GenerateOptions o = StartOptions({1, 0, z}, 40);
    const Walk w = Generate(t, c, o);
    INFO(z << ": " << w.stopped);
    CheckWalk(t, c, o, w);
    CHECK_THAT(w.stopped, !Catch::Contains("no room"));
    CHECK(Body(w).keys.back().position.y > (steps - 2) * rise);
  }
}

namespace {

// A biped's feet (L and R) after each touch-down but the first two: the least gap between them
// across `heading` (left of it on the world up, L's side positive), the most they lie apart in
// height, and the most a foot's touch-down rose above its lift-off.
struct BipedStance {
  double least_gap = 1, most_apart = 0, most_climbed = 0;
};

BipedStance Stance(const Walk& w, const Vec3& heading) {
  std::vector<std::pair<double, std::pair<int, Vec3>>> ends;
  for (const WalkTrack& track : w.tracks)
    for (const WalkKey& k : track.keys)
      if (track.kind == TrackKind::kFoot && k.phase != KeyPhase::kMid)
        ends.push_back({k.frame, {track.name == "L" ? 0 : 1, k.position}});
  std::stable_sort(ends.begin(), ends.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  const Vec3 left{heading.z, 0, -heading.x};
  Vec3 at[2] = {ends.front().second.second, ends.front().second.second};
  BipedStance out;
  for (size_t i = 0; i < ends.size(); ++i) {
    const int f = ends[i].second.first;
    out.most_climbed = std::max(out.most_climbed, ends[i].second.second.y - at[f].y);
    at[f] = ends[i].second.second;
    if (i < 2) continue;
    out.least_gap = std::min(out.least_gap, Dot(at[0] - at[1], left));
    out.most_apart = std::max(out.most_apart, std::fabs(at[0].y - at[1].y));
  }
  return out;
}

}  // namespace

TEST_CASE("A biped going down stairs at a slant steps down them, its feet kept apart",
          "[steps][generator]") {
  // Its central locator, placed lead/2 above the pair's rest, snapped back onto the nose of the
  // tread its feet stood on (nearer than the tread below): heading down at 45 degrees to the
  // treads or less, a biped walked along that nose for every step it was given, its feet
  // crossing. The locator now lands on the ground below where it was placed. Point stairs, and
  // a resampled stair mesh (samples spread unevenly, both faces' normals at its noses).
  const Character c = LoadShipped("biped");
  const int steps = 12;
  const double rise = 0.18, run = 0.3, spacing = 0.03;
  RawSamples mesh;
  MeshSampleOptions mo;
  mo.separation = spacing;
  mo.smooth_normals = false;
  REQUIRE(SampleMesh(MakeStairsMesh(steps, rise, run, 8), mo, &mesh, nullptr) == Status::kOk);
  for (const bool resampled : {false, true}) {
    Terrain t = resampled ? LoadTerrain(mesh, spacing * 2 / 3)
                          : LoadTerrain(MakeStairs(steps, rise, run, 8, spacing), spacing);
    const double first_top = resampled ? rise : 0, top = first_top + (steps - 1) * rise;
    for (const double deg : {20.0, 30.0, 45.0, 60.0, 90.0}) {
      GenerateOptions o = StartOptions({2, top, run * steps - 0.1}, 12);
      const double a = deg * kPi / 180;
      o.heading = {std::cos(a), 0, -std::sin(a)};
      const Walk w = Generate(t, c, o);
      INFO((resampled ? "mesh " : "points ") << deg << " deg: " << w.stopped);
      CheckWalk(t, c, o, w);
      CHECK(w.stopped.empty());
      auto depth = [&](const Vec3& p) { return FlightDepth(p, steps, rise, run, first_top); };
      CHECK(DeepestSwing(w, depth) <= spacing);
      // 2.5 treads down or more in 12 steps.
      CHECK(Body(w).keys.back().position.y < Body(w).keys.front().position.y - 2.5 * rise);
      // The feet's gap across the heading after each touch-down: never under a quarter of
      // their rest gap (0.24), let alone crossed; the feet never more than a tread apart in
      // height (straight down, the next tread's nose is still the foothold, not the tread
      // after it below the place), and no foot climbing back up.
      const BipedStance stance = Stance(w, o.heading);
      CHECK(stance.least_gap >= 0.25 * 0.24);
      CHECK(stance.most_apart <= rise + 0.01);
      CHECK(stance.most_climbed <= 0.01);
    }
  }
}

TEST_CASE("A biped goes down stairs with risers near its max_rise at a slant",
          "[steps][generator]") {
  // Risers of 30 to 38 cm (max_rise 40), 45 to 60 degrees to the treads: the place lay over a
  // tread more than max_rise below, so the central locator, snapped back onto the nose the feet
  // stood on, did not land on the tread between (no ground below the place), and the biped
  // walked along the top tread for every step it was given. A place in the air down to the
  // ground found below the other lines now lands there.
  const Character c = LoadShipped("biped");
  const int treads = 8;
  const double spacing = 0.03;
  for (const auto& [rise, run] :
       std::vector<std::pair<double, double>>{{0.38, 0.3}, {0.32, 0.2}, {0.3, 0.25}}) {
    Terrain t = LoadTerrain(MakeStairs(treads, rise, run, 8, spacing), spacing);
    for (const double deg : {50.0, 60.0}) {
      GenerateOptions o = StartOptions({2, (treads - 1) * rise, run * treads - 0.15}, 24);
      const double a = deg * kPi / 180;
      o.heading = {std::cos(a), 0, -std::sin(a)};
      const Walk w = Generate(t, c, o);
      INFO(rise << " x " << run << " at " << deg << " deg: " << w.stopped);
      CheckWalk(t, c, o, w);
      double lowest = (treads - 1) * rise;
      for (const WalkTrack& track : w.tracks)
        for (const WalkKey& k : track.keys)
          if (track.kind == TrackKind::kFoot && k.phase == KeyPhase::kEnd)
            lowest = std::min(lowest, k.position.y);
      CHECK(lowest <= rise + 1e-6);  // down to the first tread above the ground, or the ground
      const BipedStance stance = Stance(w, o.heading);
      CHECK(stance.least_gap >= 0.25 * 0.24);
      CHECK(stance.most_climbed <= 0.01);
    }
  }
}

TEST_CASE("A biped climbing stairs at a slant keeps its feet apart and its heading",
          "[steps][generator]") {
  // Climbing at 15 degrees to the treads or less, its central locator snapped onto the next
  // tread's nose, uphill of the heading, and drew the downhill foot's target across the other
  // foot: the feet crossed at every step (18 of 180 walks up made stairs). A foothold lined up
  // with its mate is now asked again aimed outward, to three quarters of the rest gap. The
  // body climbed a tread a step whatever its heading, its way bending up the flight (12
  // degrees to the treads walked at 21 to 27): the locator now keeps its place across the
  // heading, at the height of the nose it snapped to.
  const Character c = LoadShipped("biped");
  const int steps = 12;
  struct Flight {
    double rise, run, spacing, deg;
  };
  for (const Flight& f : {Flight{0.15, 0.3, 0.06, 12}, Flight{0.25, 0.3, 0.06, 12},
                          Flight{0.2, 0.35, 0.05, 10}, Flight{0.2, 0.3, 0.03, 5}}) {
    Terrain t = LoadTerrain(MakeStairs(steps, f.rise, f.run, 10, f.spacing), f.spacing);
    for (const double side : {1.0, -1.0}) {
      GenerateOptions o = StartOptions({side > 0 ? 1.0 : 9.0, f.rise, 1.5 * f.run}, 12);
      const double a = f.deg * kPi / 180;
      o.heading = {side * std::cos(a), 0, std::sin(a)};
      const Walk w = Generate(t, c, o);
      INFO(f.rise << " x " << f.run << " every " << f.spacing << " at " << f.deg << " deg, "
                  << (side > 0 ? "+x: " : "-x: ") << w.stopped);
      CheckWalk(t, c, o, w);
      CHECK(w.stopped.empty());
      auto depth = [&](const Vec3& p) { return FlightDepth(p, steps, f.rise, f.run, 0); };
      CHECK(DeepestSwing(w, depth) <= f.spacing);
      CHECK(Stance(w, o.heading).least_gap >= 0.25 * 0.24);
      // The way walked, seen from above, within 5 degrees of the heading (it went 6 to 16 off).
      const Vec3 way = Body(w).keys.back().position - Body(w).keys.front().position;
      const double off_deg = std::atan2(way.z, std::fabs(way.x)) * 180 / kPi - f.deg;
      CHECK(std::fabs(off_deg) <= 5);
      CHECK(std::hypot(way.x, way.z) >= 2.5);
    }
  }
}

TEST_CASE(
    "A biped walking along a flight steps down off a nose, its swing hooked out over the "
    "tread below",
    "[steps][generator]") {
  // Turned onto a tread by its path, a biped straddling a riser walks along the flight, one
  // foot just behind a nose. Its step down lands at the foot of that riser: every arc there
  // dropped past the nose, and raising the mid key never cleared it (the walk stopped, "the
  // foothold ... leans 90 deg": the riser, the best reason among the refused tries). The mid
  // key now hooks out from the riser over the tread below.
  const Character c = LoadShipped("biped");
  const int steps = 14;
  const double rise = 0.2, run = 0.25, spacing = 0.02;
  Terrain t = LoadTerrain(MakeStairs(steps, rise, run, 10, spacing), spacing);
  const Vec3 top{5, (steps - 1) * rise, 3.4};
  for (const auto& path : {std::vector<Vec3>{{5, 1.2, 1.5}, {1, 1.2, 1.5}},
                           std::vector<Vec3>{{8, 1.8, 2.4}, {1, 1.8, 2.4}}}) {
    const GenerateOptions o = PathOptions({path[0].x, top.y, top.z}, path, 80);
    const Walk w = Generate(t, c, o);
    INFO("along z = " << path[1].z << ": " << w.stopped);
    CheckWalk(t, c, o, w);
    CHECK(w.stopped.empty());
    auto depth = [&](const Vec3& p) { return FlightDepth(p, steps, rise, run, 0); };
    CHECK(DeepestSwing(w, depth) <= spacing);
    // At the goal, seen from above (within the last waypoint's half step).
    const Vec3 end = Body(w).keys.back().position;
    CHECK(std::hypot(end.x - path[1].x, end.z - path[1].z) <= 0.5 * c.step_length + 0.1);
  }
}

TEST_CASE("An upright body walks on under a roof above it, neither stopped nor raised toward it",
          "[steps][generator]") {
  // A roof 1.6 m up modelled as one face (samples facing up only) over a biped 0.95 m tall:
  // body points under it lie behind its samples' plane, which stopped the walk ("no room") and
  // raised the body toward it.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(FloorAndSlab(1.6, 1.6, false), 0.04);
  const GenerateOptions o = StartOptions({1.5, 0, 1.5}, 8);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CheckWalk(t, c, o, w);
  CHECK(w.stopped.empty());
  for (const WalkKey& k : Body(w).keys) CHECK(k.position.y == Approx(c.body_height).margin(1e-6));
}

TEST_CASE("A biped steps over a kerb lower than its step height", "[steps][generator]") {
  // A floor sampled every centimetre, a kerb 2 cm thick across the way: with the feet either
  // side of it, its top crossed the spine, and kerbs 3 to 6 cm tall stopped the walk with "no
  // room for the body ... (an overhang or a ceiling lower than body_height)".
  const Character c = LoadShipped("biped");
  const double s = 0.01;
  for (const double height : {0.03, 0.05, 0.06, 0.1}) {
    INFO("kerb " << height);
    // The floor (x from 0 to 2, z from 0 to 3) but under the kerb; the kerb's faces sampled
    // from the floor up, its top across.
    RawSamples kerb;
    for (int i = 0; i <= 200; ++i) {
      const double x = i * s;
      for (int k = 0; k <= 300; ++k)
        if (k < 150 || k > 152) kerb.push_back({x, 0, k * s}, {0, 1, 0});
      for (int j = 0; j * s <= height + 1e-9; ++j) {
        kerb.push_back({x, j * s, 1.5}, {0, 0, -1});
        kerb.push_back({x, j * s, 1.52}, {0, 0, 1});
      }
      for (int k = 150; k <= 152; ++k) kerb.push_back({x, height, k * s}, {0, 1, 0});
    }
    Terrain t = LoadTerrain(kerb, s);
    const GenerateOptions o = StartOptions({1, 0, 0.8}, 6);
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CheckWalk(t, c, o, w);
    CHECK(w.stopped.empty());
    CHECK(Body(w).keys.back().position.z > 2);
  }
}

TEST_CASE("A biped walks straight beside a wall, and stops before a block for its height",
          "[steps][generator]") {
  // A floor and a block 2 m tall across z from 2 to 3 m. Walking along +x with its body 0.24 m
  // from the block's face: its pairs' central locators snapped onto the face (nearer than the
  // floor to a point 0.26 m up) and drew the feet sideways into it; the spine's check then took
  // the face for an overhang. Walking into the block: the stop named "no room for the body"
  // (an overhang or a ceiling) instead of the too-steep face ahead.
  const Character c = LoadShipped("biped");
  const double s = 0.04;
  Terrain t = LoadTerrain(FloorWithBlock(s, 150, 100, 2, 3, 2, 50, true), s);
  GenerateOptions beside = StartOptions({0.5, 0, 2 - 0.24}, 12);
  beside.heading = {1, 0, 0};
  const Walk w = Generate(t, c, beside);
  INFO(w.stopped);
  CheckWalk(t, c, beside, w);
  CHECK(w.stopped.empty());
  for (const WalkKey& k : Body(w).keys) CHECK(k.position.z == Approx(2 - 0.24).margin(0.03));
  // Full steps: as far as in the open, 1.2 m from the block (aimed at the wall's height, steps
  // beside it were a third of step_length).
  GenerateOptions open = beside;
  open.start.z = 0.8;
  const Walk away = Generate(t, c, open);
  REQUIRE(away.stopped.empty());
  const double travel = Body(w).keys.back().position.x - Body(w).keys.front().position.x;
  CHECK(travel >= 0.95 * (Body(away).keys.back().position.x - Body(away).keys.front().position.x));
  CHECK(travel > 0.4 * c.step_length * beside.steps);
  const GenerateOptions into = StartOptions({3, 0, 1}, 40);
  const Walk stopped = Generate(t, c, into);
  INFO(stopped.stopped);
  CheckWalk(t, c, into, stopped);
  CHECK_THAT(stopped.stopped, Catch::Contains("too steep") || Catch::Contains("max_rise"));
  CHECK_THAT(stopped.stopped, !Catch::Contains("no room"));
}

TEST_CASE("A start under a thin ceiling stays on its underside", "[steps][generator]") {
  // A ceiling 3 cm thick (underside facing down at y = 0.3, top facing up at 0.33), a hexapod
  // started at its underside: the start's probe for level ground took the top, through it.
  RawSamples ceiling;
  const double s = 0.01;
  for (int i = 0; i <= 200; ++i) {
    for (int k = 0; k <= 200; ++k) {
      ceiling.push_back({i * s, 0.3, k * s}, {0, -1, 0});
      ceiling.push_back({i * s, 0.33, k * s}, {0, 1, 0});
    }
  }
  Terrain t = LoadTerrain(ceiling, s);
  const Character c = LoadShipped("hexapod");
  GenerateOptions o;
  o.has_start = true;
  o.start = {1, 0.3, 1};
  o.steps = 4;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  for (const WalkTrack& track : w.tracks)
    if (track.kind == TrackKind::kFoot) CHECK(track.keys.front().position.y == Approx(0.3));
}

TEST_CASE("A stop on ground facing down names the likely causes", "[steps][generator]") {
  // Flat ground whose normals face down (the underside of a thin slab, or inward faces): the
  // stop said only that the ground leans 180 degrees.
  const Character c = LoadShipped("biped");
  const double spacing = 0.05;
  RawSamples ground = MakeFlat(80, spacing, 0);
  for (Vec3& n : ground.normals) n = {0, -1, 0};
  Terrain t = LoadTerrain(ground, spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {2, 0, 2};
  o.steps = 4;
  const Walk w = Generate(t, c, o);
  CHECK_THAT(w.stopped, Catch::Contains("leans 180") && Catch::Contains("it faces down") &&
                            Catch::Contains("separation below its thickness"));
}

TEST_CASE("An insect on a beam narrower than it is told it may be too wide for it",
          "[steps][generator]") {
  // A 4 cm beam, its top and two 10 cm sides sampled every centimetre: a hexapod's foot reaches
  // round a side and finds it facing away from its up. The hint named only thin surfaces and
  // inward faces, neither of which applies.
  const Character c = LoadShipped("hexapod");
  const double spacing = 0.01;
  RawSamples beam;
  for (int k = 0; k <= 300; ++k) {
    const double z = k * spacing;
    for (int i = -2; i <= 2; ++i) beam.points.push_back({i * spacing, 0, z});
    beam.normals.resize(beam.points.size(), {0, 1, 0});
    for (int j = 1; j <= 10; ++j) {
      beam.points.push_back({-0.02, -j * spacing, z}), beam.normals.push_back({-1, 0, 0});
      beam.points.push_back({0.02, -j * spacing, z}), beam.normals.push_back({1, 0, 0});
    }
  }
  Terrain t = LoadTerrain(beam, spacing);
  GenerateOptions o = StartOptions({0, 0, 0.5}, 30);
  o.heading = {0, 0, 1};
  const Walk w = Generate(t, c, o);
  CHECK_THAT(w.stopped, Catch::Contains("it faces away from the character's up") &&
                            Catch::Contains("wider than the beam or ledge it walks along"));
  CHECK_THAT(w.stopped, !Catch::Contains("it faces down"));
}

TEST_CASE("Multipeds climb a wall, others stop at it", "[steps][generator]") {
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double spacing = c.step_length / 10;
    const Vec3 size{8 * c.reach, 4 * c.reach, 8 * c.reach};
    Terrain t = LoadTerrain(MakeRoom(size, spacing), spacing);
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = {size.x / 2, 0, 5 * c.reach};
    o.steps = static_cast<int>((3 * c.reach + 2 * c.reach) / (c.step_length / 2)) + 4;
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CheckWalk(t, c, o, w);
    double highest_foot = 0;
    bool on_wall = false;
    for (const WalkTrack& tr : w.tracks)
      for (const WalkKey& k : tr.keys)
        if (tr.kind == TrackKind::kFoot && k.phase == KeyPhase::kEnd) {
          highest_foot = std::max(highest_foot, k.position.y);
          on_wall |= k.normal.z < -0.99;
        }
    if (name == "hexapod" || name == "octopod") {
      CHECK(w.stopped.empty());
      CHECK(on_wall);
      CHECK(highest_foot > c.reach);
      CHECK(Body(w).keys.back().position.y > c.reach);
    } else {
      CHECK_THAT(w.stopped, Catch::Contains("step "));
      CHECK_FALSE(on_wall);
    }
  }
}

TEST_CASE("Multipeds start on a wall or a ceiling", "[steps][generator]") {
  const Character c = LoadShipped("hexapod");
  const Vec3 size{2, 2, 2};
  Terrain t = LoadTerrain(MakeRoom(size, 0.012), 0.012);
  SECTION("on the wall z = 0, facing up it") {
    GenerateOptions o;
    o.has_start = true;
    o.start = {1, 0.8, 0};
    o.heading = {0, 1, 0};
    o.steps = 10;
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CHECK(w.stopped.empty());
    CheckWalk(t, c, o, w);
    const auto& body = Body(w).keys;
    CHECK(body.back().position.y - body.front().position.y > 3 * c.step_length);
    CHECK(BodyUp(Body(w).rotations.back()).z > 0.99);
    CHECK(body.back().position.z == Approx(c.body_height).margin(1e-6));
  }
  SECTION("on the ceiling, facing +X") {
    GenerateOptions o;
    o.has_start = true;
    o.start = {0.6, 2, 1};
    o.heading = {1, 0, 0};
    o.steps = 10;
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    CHECK(w.stopped.empty());
    CheckWalk(t, c, o, w);
    const auto& body = Body(w).keys;
    CHECK(body.back().position.x - body.front().position.x > 3 * c.step_length);
    CHECK(BodyUp(Body(w).rotations.back()).y < -0.99);
    CHECK(body.back().position.y == Approx(2 - c.body_height).margin(1e-6));
  }
}

TEST_CASE("A gait of one group keys every touch-down, its feet lifting from there",
          "[steps][generator]") {
  // The quadruped with all four feet in one group (a hop), and a single foot.
  Character hop = LoadShipped("quadruped");
  hop.gait = {{0, 1, 2, 3}};
  Character one = LoadShipped("biped");
  one.feet.resize(1);
  one.gait = {{0}};
  one.pairs = {{0}};
  for (const Character& c : {hop, one}) {
    INFO(c.feet.size() << " feet");
    const Walk w = CheckedWalkOnFlat(c, 9);
    for (const WalkTrack& tr : w.tracks) {
      if (tr.kind != TrackKind::kFoot) continue;
      int ends = 0, mids = 0;
      for (const WalkKey& k : tr.keys)
        ends += k.phase == KeyPhase::kEnd, mids += k.phase == KeyPhase::kMid;
      CHECK(mids == 9);
      CHECK(ends == 9);  // every step's touch-down (it was only the last one's)
    }
  }
}

TEST_CASE("Keys at a fractional start frame fall on the frames of an integer one, shifted",
          "[steps][generator]") {
  // start_frame + k * frames_per_step computed once for each frame: summed step by step, a
  // touch-down and the next lift-off differed by a rounding, so a gait of one group got a second
  // lift-off key beside its touch-down (and glTF refused two keys that close), and a stopped
  // walk took back its last kept step's touch-down with the stopped step's keys.
  Character hop = LoadShipped("quadruped");
  hop.gait = {{0, 1, 2, 3}};
  const Character biped = LoadShipped("biped");
  Terrain flat = LoadTerrain(MakeFlat(200, 0.05, 0), 0.05);
  // Flat ground with a slab over it, lower than the biped's body (it stops under its edge).
  RawSamples slab = MakeFlat(200, 0.05, 0);
  for (int k = 0; k < 200; ++k)
    for (int i = 0; i < 200; ++i)
      if (k * 0.05 > 6) slab.push_back({i * 0.05, 0.6, k * 0.05}, {0, -1, 0});
  Terrain under_slab = LoadTerrain(slab, 0.05);
  int stops = 0;
  for (const int frames : {8, 19}) {
    for (const double start : {1.0, 0.13, 0.23, 8.355, 0.05525882872479637}) {
      INFO(frames << " frames a step from frame " << start);
      for (Character c : {hop, biped}) {
        c.frames_per_step = frames;
        GenerateOptions o;
        o.has_start = true;
        o.start = {5, 0, 2};
        o.steps = 16;
        o.start_frame = start;
        GenerateOptions at_zero = o;
        at_zero.start_frame = 0;
        for (Terrain* t : {&flat, &under_slab}) {
          const Walk w = Generate(*t, c, o), from_zero = Generate(*t, c, at_zero);
          CHECK(w.stopped.empty() == from_zero.stopped.empty());
          stops += !w.stopped.empty();
          CheckWalk(*t, c, o, w);
          REQUIRE(w.tracks.size() == from_zero.tracks.size());
          for (size_t i = 0; i < w.tracks.size(); ++i) {
            const auto &keys = w.tracks[i].keys, &zero_keys = from_zero.tracks[i].keys;
            INFO(w.tracks[i].name);
            REQUIRE(keys.size() == zero_keys.size());
            for (size_t j = 0; j < keys.size(); ++j) {
              // Every key on start + (a half-step count) * frames_per_step / 2, exactly.
              const double half_steps = 2 * zero_keys[j].frame / frames;
              CHECK(half_steps == std::round(half_steps));
              CHECK(keys[j].frame == start + 0.5 * half_steps * frames);
              CHECK(keys[j].phase == zero_keys[j].phase);
              CHECK(keys[j].position == zero_keys[j].position);
              if (j > 0) CHECK(keys[j].frame > keys[j - 1].frame);
            }
          }
        }
      }
    }
  }
  CHECK(stops >= 10);  // the biped under the slab, at every start frame
}

TEST_CASE("Feet whose rests are off the body's origin walk straight", "[steps][generator]") {
  // One foot 0.1 to the left of and 0.2 ahead of the body, and a biped shifted 0.3 sideways:
  // their walks follow the heading (each drifted by its rests' offset every step).
  Character one = LoadShipped("biped");
  one.feet.resize(1);
  one.feet[0].rest = {0.1, 0, 0.2};
  one.gait = {{0}};
  one.pairs = {{0}};
  Character shifted = LoadShipped("biped");
  for (FootSpec& f : shifted.feet) f.rest.x += 0.3;
  shifted.reach += 0.3;
  for (const Character& c : {one, shifted}) {
    INFO(c.feet.size() << " feet");
    const Walk w = CheckedWalkOnFlat(c, 10);
    const auto& body = Body(w).keys;
    CHECK(std::fabs(body.back().position.x - body.front().position.x) < 0.06);
    CHECK(body.back().position.z - body.front().position.z > 2);
  }
}

TEST_CASE("A cliff stops the walk with the step, the position and the keys so far",
          "[steps][generator]") {
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    const double spacing = c.step_length / 10, edge = 8 * c.reach;
    RawSamples s;
    const int n = static_cast<int>(10 * c.reach / spacing);
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < n; ++i) {
        const double x = i * spacing, z = k * spacing;
        s.push_back({x, z < edge ? 0 : -20 * c.reach, z}, {0, 1, 0});
      }
    Terrain t = LoadTerrain(s, spacing);
    INFO(name);
    GenerateOptions o;
    o.has_start = true;
    o.start = {5 * c.reach, 0, 3 * c.reach};
    o.steps = 200;
    const Walk w = Generate(t, c, o);
    INFO(w.stopped);
    REQUIRE_FALSE(w.stopped.empty());
    const size_t done = StepsDone(w);
    CHECK(done > 4);
    CHECK_THAT(w.stopped, Catch::StartsWith("step " + std::to_string(done + 1) + ": foot "));
    CHECK_THAT(w.stopped, Catch::Contains("cliff"));
    // The first refusal (the step as meant), then how many other tries failed too.
    CHECK_THAT(w.stopped,
               Catch::Contains("(8 more tries, shorter, longer or aimed down, refused too)"));
    CHECK_THAT(w.stopped, Catch::Contains("keys up to step " + std::to_string(done) + " kept"));
    // Samples a tenth of a step apart are fine enough: no advice to resample.
    CHECK_THAT(w.stopped, !Catch::Contains("resample"));
    CheckWalk(t, c, o, w);
    // Nothing lost: every foot ends planted at the edge side, with all its steps keyed.
    for (const WalkTrack& tr : w.tracks) {
      if (tr.kind != TrackKind::kFoot) continue;
      CHECK(tr.keys.back().phase == KeyPhase::kEnd);
      CHECK(tr.keys.back().position.z < edge);
      CHECK(tr.keys.back().position.y == Approx(0).margin(1e-6));
    }
  }
}

TEST_CASE("A multiped with its feet in a line walks up a ramp (no plane to fit: averaged normal)",
          "[steps][generator]") {
  // Four feet on the body's axis: the plane of the feet is undefined, so the body's up falls
  // back to the feet's averaged normal, and nothing turns NaN.
  Character worm;
  std::string error;
  REQUIRE(ParseCharacter(R"({"format": "footfall-character", "version": 1, "name": "worm",
    "feet": [{"name": "A", "rest": [0, 0, 0.3]}, {"name": "B", "rest": [0, 0, 0.1]},
             {"name": "C", "rest": [0, 0, -0.1]}, {"name": "D", "rest": [0, 0, -0.3]}],
    "gait": [["A", "C"], ["B", "D"]], "pairs": [["A"], ["B"], ["C"], ["D"]],
    "step_length": 0.2, "step_height": 0.05, "body_height": 0.1, "frames_per_step": 6,
    "align_to_normal": true, "reach": 0.5})",
                         "worm", &worm, &error) == Status::kOk);
  const double spacing = 0.02, slope = 20 * kPi / 180;
  Terrain t = LoadTerrain(MakeRamp(100, 400, spacing, 20), spacing);
  GenerateOptions o;
  o.has_start = true;
  o.start = {1, std::sin(slope) * 1.0, std::cos(slope) * 1.0};
  o.steps = 12;
  const Walk w = Generate(t, worm, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, worm, o, w);
  // The body's up is the ramp's normal (every foot on the same plane, normals alike).
  const Vec3 ramp_normal{0, std::cos(slope), -std::sin(slope)};
  for (const Quat& q : Body(w).rotations) CHECK(Dot(BodyUp(q), ramp_normal) > 0.999);
}

TEST_CASE("A quadruped walks straight down stairs steeper than half its max_rise reaches",
          "[steps][generator]") {
  // Its feet's up is the treads' normal, so each target hangs at the stance's height: on 20 cm
  // rises and 25 cm treads the front feet aimed 20 cm over the next tread, and the tries aimed
  // down by half of max_rise (17.5 cm) found nothing within the tolerance: it stopped at its
  // first step. The last tries aim down by the whole max_rise.
  const Character quadruped = LoadShipped("quadruped");
  const int treads = 20;
  const double rise = 0.2, run = 0.25;
  REQUIRE(rise > 0.5 * quadruped.max_rise);
  REQUIRE(rise <= quadruped.max_rise);
  Terrain t = LoadTerrain(MakeStairs(treads, rise, run, 6, 0.03), 0.03);
  const int from = treads - 2;
  GenerateOptions o = StartOptions({3, from * rise, (from + 0.5) * run}, 8);
  o.heading = {0, 0, -1};
  const Walk w = Generate(t, quadruped, o);
  INFO(w.stopped);
  CheckWalk(t, quadruped, o, w);
  CHECK(w.stopped.empty());
  // Every foot went down: its last key at least two treads below its first (samples are
  // stored in single precision).
  for (const WalkTrack& track : w.tracks) {
    if (track.kind != TrackKind::kFoot) continue;
    INFO(track.name);
    REQUIRE(track.keys.size() > 2);
    CHECK(track.keys.back().position.y <= track.keys.front().position.y - 2 * rise + 1e-5);
  }
}
