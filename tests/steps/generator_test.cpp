// The step generator on generated terrain, for every shipped character: slopes, stairs, a
// sphere, a wall, a path with a 90-degree turn, a cliff, crowds. Every walk is checked against
// the invariants of walk_checks.h.
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
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Terrain sizes follow the character: a biped's terrain is ~6 times an insect's.
double Scale(const Character& c) { return c.step_length / 0.7; }

Vec3 BodyForward(const Quat& q) {
  return {2 * (q.x * q.z + q.w * q.y), 2 * (q.y * q.z - q.w * q.x),
          1 - 2 * (q.x * q.x + q.y * q.y)};
}

Vec3 BodyUp(const Quat& q) {
  return {2 * (q.x * q.y - q.w * q.z), 1 - 2 * (q.x * q.x + q.z * q.z),
          2 * (q.y * q.z + q.w * q.x)};
}

size_t StepsDone(const Walk& w) {
  for (const WalkTrack& t : w.tracks)
    if (t.kind == TrackKind::kBody) return t.keys.size() - 1;
  return 0;
}

const WalkTrack& Body(const Walk& w) {
  for (const WalkTrack& t : w.tracks)
    if (t.kind == TrackKind::kBody) return t;
  FAIL("no body track");
  return w.tracks.front();
}

// The deepest any swing (start->mid, mid->end, sampled every 1/200) passes into the solid whose
// depth at a point `depth_at` gives (positive inside).
template <typename Depth>
double DeepestSwing(const Walk& w, const Depth& depth_at) {
  double deepest = 0;
  for (const WalkTrack& t : w.tracks) {
    if (t.kind != TrackKind::kFoot) continue;
    for (size_t i = 0; i + 2 < t.keys.size(); ++i) {
      if (t.keys[i + 1].phase != KeyPhase::kMid) continue;
      const Vec3 &a = t.keys[i].position, &m = t.keys[i + 1].position, &b = t.keys[i + 2].position;
      for (int j = 1; j < 200; ++j) {
        deepest = std::max(deepest, depth_at(Lerp(a, m, j / 200.0)));
        deepest = std::max(deepest, depth_at(Lerp(m, b, j / 200.0)));
      }
    }
  }
  return deepest;
}

// How deep p lies in a flight of `steps` stairs along +z with flat faces: column k (z from
// k * run to (k + 1) * run) solid up to first_top + k * rise, its riser at z = k * run; before
// the flight (z < 0) the floor y = 0, past it the top tread's height (positive inside).
double FlightDepth(const Vec3& p, int steps, double rise, double run, double first_top) {
  const double k = std::clamp(std::floor(p.z / run), -1.0, steps - 1.0);
  const double top = k < 0 ? 0 : first_top + k * rise;
  if (p.y >= top) return 0;
  const double below = top - p.y;
  const double lower = k < 1 ? 0 : first_top + (k - 1) * rise;  // the column in front
  return k >= 0 && p.y > lower && p.z < (k + 1) * run ? std::min(below, p.z - k * run) : below;
}

// A floor (y = 0) of (nx + 1) x (nz + 1) samples `s` apart, cut across by a block from z0 to z1,
// `height` tall: its faces (-z at z0, +z at z1) sampled in `rows` rows up to its top, and its
// top on the floor's lattice between them (with its edges when `edges_on_top`, else the faces'
// top rows hold them).
RawSamples FloorWithBlock(double s, int nx, int nz, double z0, double z1, double height, int rows,
                          bool edges_on_top) {
  RawSamples out;
  for (int i = 0; i <= nx; ++i) {
    const double x = i * s;
    for (int k = 0; k <= nz; ++k) {
      const double z = k * s;
      const bool on = z >= z0 - 1e-9 && z <= z1 + 1e-9;
      const bool edge = std::fabs(z - z0) < 1e-9 || std::fabs(z - z1) < 1e-9;
      if (!on) out.push_back({x, 0, z}, {0, 1, 0});
      if (on && (edges_on_top || !edge)) out.push_back({x, height, z}, {0, 1, 0});
    }
    for (int j = 1; j < rows + !edges_on_top; ++j) {
      out.push_back({x, j * height / rows, z0}, {0, 0, -1});
      out.push_back({x, j * height / rows, z1}, {0, 0, 1});
    }
  }
  return out;
}

// How deep p lies below that floor or in that block (positive inside).
double FloorOrBlockDepth(const Vec3& p, double z0, double z1, double height) {
  if (p.y < 0) return -p.y;
  if (p.z > z0 && p.z < z1 && p.y < height) return std::min({p.z - z0, z1 - p.z, height - p.y});
  return 0;
}

// Walks 12 steps from `start` along +Z (`forward`) or -Z and checks the walk: no stop, every
// invariant of CheckWalk, and the body rising by more than `rise` (a negative `rise`: falling by
// more than -rise).
Walk WalkTwelveSteps(Terrain& t, const Character& c, const Vec3& start, bool forward, double rise) {
  GenerateOptions o;
  o.has_start = true;
  o.start = start;
  o.heading = {0, 0, forward ? 1.0 : -1.0};
  o.steps = 12;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CHECK(StepsDone(w) == 12);
  CheckWalk(t, c, o, w);
  const auto& body = Body(w).keys;
  const double climbed = body.back().position.y - body.front().position.y;
  if (rise >= 0) {
    CHECK(climbed > rise);
  } else {
    CHECK(climbed < rise);
  }
  return w;
}

// `steps` steps of c from (5, 0, 2) along +Z on a flat floor 10 m wide: not stopped, and every
// invariant of CheckWalk held.
Walk CheckedWalkOnFlat(const Character& c, int steps) {
  Terrain t = LoadTerrain(MakeFlat(200, 0.05, 0), 0.05);
  GenerateOptions o;
  o.has_start = true;
  o.start = {5, 0, 2};
  o.steps = steps;
  Walk w = Generate(t, c, o);
  REQUIRE(w.stopped.empty());
  CheckWalk(t, c, o, w);
  return w;
}

// One character starting at `start`, walking `steps` steps.
GenerateOptions StartOptions(const Vec3& start, int steps) {
  GenerateOptions o;
  o.has_start = true;
  o.start = start;
  o.steps = steps;
  return o;
}

// A flat square `side` wide at y = 0, sampled at a tenth of c's step, loaded.
Terrain FlatFor(const Character& c, double side) {
  const double spacing = c.step_length / 10;
  return LoadTerrain(MakeFlat(static_cast<int>(side / spacing), spacing, 0), spacing);
}

// A crowd of `crowd` characters `spacing` apart around `start`, walking `steps` steps.
GenerateOptions CrowdOptions(const Vec3& start, int steps, int crowd, double spacing) {
  GenerateOptions o = StartOptions(start, steps);
  o.crowd = crowd;
  o.crowd_spacing = spacing;
  return o;
}

}  // namespace

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
  // outward by half the spacing.
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
  CHECK_THAT(w.stopped, Catch::StartsWith("step 10001: the path's goal (5.0000, 0.0000, 2.0000) "
                                          "is still ") &&
                            Catch::Contains("after 10000 steps, the most a path walk takes "
                                            "without --steps"));
  CHECK(StepsDone(w) == 10000);
  // With --steps the walk is as asked: no stop, but a note of how far the goal still is (it
  // ended short of it saying nothing).
  o.steps = 50;
  const Walk asked = Generate(t, c, o);
  CHECK(asked.stopped.empty());
  REQUIRE(asked.notes.size() == 1);
  CHECK_THAT(asked.notes[0],
             Catch::StartsWith("the path's goal (5.0000, 0.0000, 2.0000) is still ") &&
                 Catch::EndsWith(" away after the 50 steps asked for (without "
                                 "--steps a path walk goes on to its goal, up to "
                                 "10000 steps)"));
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
               Catch::Contains("(6 more tries, shorter, longer or aimed down, refused too)"));
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

namespace {

// A real embedded session that counts the batch calls it serves.
class CountingSession final : public TerrainSession {
 public:
  CountingSession() : inner_(MakeEmbeddedSession()) {}
  Status LoadServerFile(const std::string& p, const TerrainLoadOptions& o,
                        TerrainHandle* out) override {
    return inner_->LoadServerFile(p, o, out);
  }
  Status LoadSamples(const RawSamples& s, const std::string& n, TerrainHandle* out) override {
    return inner_->LoadSamples(s, n, out);
  }
  Status Info(TerrainHandle t, TerrainInfo* out) override { return inner_->Info(t, out); }
  Status Unload(TerrainHandle t) override { return inner_->Unload(t); }
  Status Snap(TerrainHandle t, const Vec3* p, size_t n, Foothold* out) override {
    ++snaps;
    return inner_->Snap(t, p, n, out);
  }
  Status Normal(TerrainHandle t, const Vec3* p, size_t n, Foothold* out) override {
    ++snaps;
    return inner_->Normal(t, p, n, out);
  }
  Status Next(TerrainHandle t, const StepQuery* q, size_t n, double tol, Foothold* out) override {
    ++nexts, next_queries += n;
    return inner_->Next(t, q, n, tol, out);
  }
  std::string Describe() const override { return "counting " + inner_->Describe(); }
  bool InProcess() const override { return !remote && inner_->InProcess(); }
  size_t snaps = 0, nexts = 0, next_queries = 0;
  bool remote = false;  // says it answers out of process, as an RPC session does

 private:
  std::unique_ptr<TerrainSession> inner_;
};

}  // namespace

TEST_CASE("A crowd batches every character's queries into one call per round",
          "[steps][generator][crowd]") {
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeFlat(300, 0.012, 0);
  auto run = [&](int crowd, CountingSession* session, Walk* w) {
    TerrainHandle h;
    REQUIRE(session->LoadSamples(ground, "flat", &h) == Status::kOk);
    GenerateOptions o = CrowdOptions({1.8, 0, 1.2}, 10, crowd, 0.5);
    std::string error;
    REQUIRE(GenerateWalk(*session, h, c, o, w, &error) == Status::kOk);
    Terrain t = LoadTerrain(ground, 0.012);
    CheckWalk(t, c, o, *w);
  };
  CountingSession one, many;
  Walk w1, w9;
  run(1, &one, &w1);
  run(9, &many, &w9);
  CHECK(w9.stopped.empty());
  CHECK(many.next_queries == 9 * one.next_queries);
  CHECK(many.nexts == one.nexts);
  CHECK(many.snaps == one.snaps);
  CHECK(one.nexts == 10);  // flat ground: one Next batch per step, no retries
  // Tracks are named per character.
  CHECK(w9.tracks.size() == 9 * (c.feet.size() + 1));
  CHECK(w9.tracks.front().character == "c1");
  CHECK(w9.tracks.back().character == "c9");
}

TEST_CASE("Crowd places that snap onto another character's start are left out",
          "[steps][generator][crowd]") {
  // A 3 x 3 grid 1 m apart around (0.3, 0, 0.3) on a 10 m square: the places at -0.7 snap onto
  // the edge, 0.3 from their neighbours' starts. They stood on top of them and walked the same
  // tracks; now the five of them are left out (no tracks), each stop saying why.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(200, 0.05, 0), 0.05);
  const GenerateOptions o = CrowdOptions({0.3, 0, 0.3}, 4, 9, 1.0);
  const Walk w = Generate(t, c, o);
  std::set<std::string> characters;
  std::vector<Vec3> starts;
  for (const WalkTrack& track : w.tracks) {
    characters.insert(track.character);
    if (track.kind == TrackKind::kBody) starts.push_back(track.keys.front().position);
  }
  CHECK(characters == std::set<std::string>{"c5", "c6", "c8", "c9"});
  CHECK(w.tracks.size() == 4 * (c.feet.size() + 1));
  for (size_t i = 0; i < starts.size(); ++i)
    for (size_t j = i + 1; j < starts.size(); ++j) CHECK(Distance(starts[i], starts[j]) > 0.9);
  REQUIRE(w.stops.size() == 5);
  for (const std::string& stop : w.stops) {
    CHECK_THAT(stop, Catch::Contains("its place on the crowd's grid"));
    CHECK_THAT(stop, Catch::Contains("left out of the walk"));
  }
}

TEST_CASE("A crowd of insects on bumpy ground stands on a grid across world up",
          "[steps][generator][crowd]") {
  // The grid lay in the plane of the start sample's normal: on gentle bumps it tilted metres
  // above and below the ground at its edges, and its places snapped onto the bumps' tops
  // together (826 of 10,000 hexapods started on another's sample, the duplicates now left out).
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeHeightField(300, 300, 0.04, 0.02, 11), 0.04);
  GenerateOptions o = CrowdOptions({6, 0, 6}, 2, 400, 0.5);
  const Walk w = Generate(t, c, o);
  for (const std::string& stop : w.stops) CHECK_THAT(stop, !Catch::Contains("left out"));
  CHECK(w.tracks.size() == 400 * (c.feet.size() + 1));
}

TEST_CASE("By default a crowd walks in passes in process and all at once out of process",
          "[steps][generator][crowd]") {
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeFlat(400, 0.012, 0);  // 4.8 m square
  const int crowd = kInProcessCharactersPerPass + 1, steps = 2;
  auto run = [&](CountingSession* session, int* passes) {
    TerrainHandle h;
    REQUIRE(session->LoadSamples(ground, "flat", &h) == Status::kOk);
    GenerateOptions o = CrowdOptions({2.4, 0, 2.2}, steps, crowd, 0.1);
    o.progress = [passes, steps](int, int total) { *passes = total / steps; };
    Walk w;
    std::string error;
    REQUIRE(GenerateWalk(*session, h, c, o, &w, &error) == Status::kOk);
    CHECK(w.stopped.empty());
    return w;
  };
  CountingSession local, remote;
  remote.remote = true;
  int local_passes = 0, remote_passes = 0;
  const Walk a = run(&local, &local_passes), b = run(&remote, &remote_passes);
  CHECK(local_passes == 2);
  CHECK(remote_passes == 1);
  CHECK(local.nexts == 2 * remote.nexts);
  CHECK(local.next_queries == remote.next_queries);
  REQUIRE(a.tracks.size() == b.tracks.size());
  size_t differ = 0;
  for (size_t i = 0; i < a.tracks.size(); ++i) {
    REQUIRE(a.tracks[i].keys.size() == b.tracks[i].keys.size());
    for (size_t k = 0; k < a.tracks[i].keys.size(); ++k)
      differ += !(a.tracks[i].keys[k].position == b.tracks[i].keys[k].position);
  }
  CHECK(differ == 0);
}

TEST_CASE("A generated walk's keys share one block that its tracks keep alive",
          "[steps][generator][crowd]") {
  // 100 hexapods x 40 steps: a few megabytes of keys, a block returned to the system when the
  // last track holding it goes. After the walks are gone, new walks are generated (reusing
  // their memory), and the kept tracks must still read their own keys.
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeFlat(300, 0.02, 0), 0.02);
  GenerateOptions o = CrowdOptions({3, 0, 2}, 40, 100, 0.2);
  std::optional<WalkTrack> kept, assigned;
  WalkTrack copied;
  std::vector<WalkKey> expected, expected_assigned;
  {
    Walk w = Generate(t, c, o);
    REQUIRE(w.stopped.empty());
    const std::pmr::memory_resource* arena = w.tracks.front().memory.get();
    REQUIRE(arena != nullptr);
    for (const WalkTrack& track : w.tracks) {
      REQUIRE(track.memory.get() == arena);
      REQUIRE(track.keys.get_allocator().resource() == arena);
    }
    WalkTrack& last = w.tracks.back();  // the last character's body
    expected.assign(last.keys.begin(), last.keys.end());
    REQUIRE(expected.size() == static_cast<size_t>(o.steps + 1));
    copied = last;  // a copy's keys live on the default heap, and hold no block
    CHECK(copied.keys.get_allocator().resource() == std::pmr::get_default_resource());
    CHECK(copied.memory.get() == nullptr);
    kept.emplace(std::move(last));  // moved: the keys and their block go along
    CHECK(kept->memory.get() == arena);
    // A track of this walk assigned another walk's track keeps its keys in this walk's block,
    // and keeps that block alive.
    assigned.emplace(std::move(w.tracks.front()));
    o.start = {1, 0, 1};
    Walk other = Generate(t, c, o);
    expected_assigned.assign(other.tracks.front().keys.begin(), other.tracks.front().keys.end());
    *assigned = std::move(other.tracks.front());
    CHECK(assigned->memory.get() == arena);
    CHECK(assigned->keys.get_allocator().resource() == arena);
  }
  o.start = {4, 0, 3};
  const Walk reuse1 = Generate(t, c, o), reuse2 = Generate(t, c, o);
  REQUIRE(kept->keys.size() == expected.size());
  REQUIRE(assigned->keys.size() == expected_assigned.size());
  size_t differ = 0;
  for (size_t k = 0; k < expected.size(); ++k)
    differ += !(kept->keys[k].position == expected[k].position &&
                copied.keys[k].position == expected[k].position);
  for (size_t k = 0; k < expected_assigned.size(); ++k)
    differ += !(assigned->keys[k].position == expected_assigned[k].position);
  CHECK(differ == 0);
  // A kept track grows past its reservation.
  for (int i = 0; i < 20000; ++i) kept->keys.push_back(expected[i % expected.size()]);
  CHECK(kept->keys[expected.size() + 19999].position == expected[19999 % expected.size()].position);
  CHECK(kept->keys.front().position == expected.front().position);
}

TEST_CASE("A crowd that reserves more keys than it writes backs only the keys it writes",
          "[steps][generator][crowd]") {
  // 600 hexapods x 10,000 steps reserve about 1.2 GB of keys (4096 per foot); on a 3 m floor
  // they reach its edge and stop within a few steps. Blocks in huge pages would be backed whole
  // on their first key; beyond the huge-page budget the keys use ordinary pages.
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeFlat(150, 0.02, 0), 0.02);
  GenerateOptions o = CrowdOptions({1.5, 0, 1.5}, 10000, 600, 0.08);
  auto resident_mb = [] {
    std::ifstream statm("/proc/self/statm");
    double size = 0, resident = 0;
    statm >> size >> resident;
    return resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1 << 20);
  };
  const double before = resident_mb();
  const Walk w = Generate(t, c, o);
  const double grown = resident_mb() - before;
  CHECK_THAT(w.stopped, Catch::Contains("more characters stopped"));
  size_t keys = 0;
  for (const WalkTrack& track : w.tracks) keys += track.keys.size();
  INFO("resident memory grew " << grown << " MB for " << keys << " keys");
  CHECK(keys < 600 * 7 * 200);
  CHECK(grown < 300);
}

TEST_CASE("Generation is deterministic", "[steps][generator]") {
  const Character c = LoadShipped("quadruped");
  Terrain t = LoadTerrain(MakeHeightField(200, 200, 0.04, 0.1, 7), 0.04);
  GenerateOptions o;
  o.steps = 16;
  const Walk a = Generate(t, c, o), b = Generate(t, c, o);
  REQUIRE(a.tracks.size() == b.tracks.size());
  for (size_t i = 0; i < a.tracks.size(); ++i) {
    REQUIRE(a.tracks[i].keys.size() == b.tracks[i].keys.size());
    for (size_t k = 0; k < a.tracks[i].keys.size(); ++k)
      CHECK(a.tracks[i].keys[k].position == b.tracks[i].keys[k].position);
  }
}

TEST_CASE("A large crowd's walk is the same on one thread and on two",
          "[steps][generator][crowd]") {
  // 2,100 hexapods: enough for the generator and the engine to split their work.
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeHeightField(500, 500, 0.03, 0.01, 3);
  auto run = [&](int threads) {
    auto session = MakeEmbeddedSession(threads);
    TerrainHandle h;
    REQUIRE(session->LoadSamples(ground, "bumps", &h) == Status::kOk);
    GenerateOptions o = CrowdOptions({7.5, 0, 7}, 4, 2100, 0.3);
    o.threads = threads;
    Walk w;
    std::string error;
    INFO(error);
    REQUIRE(GenerateWalk(*session, h, c, o, &w, &error) == Status::kOk);
    return w;
  };
  const Walk one = run(1), two = run(2);
  CHECK(one.stopped == two.stopped);
  REQUIRE(one.tracks.size() == two.tracks.size());
  size_t left_out = 0;  // crowd places at the terrain's edge snapped onto others' starts
  for (const std::string& stop : one.stops)
    left_out += stop.find("left out of the walk") != std::string::npos;
  CHECK(left_out < 100);
  REQUIRE(one.tracks.size() == (2100 - left_out) * (c.feet.size() + 1));
  size_t keys = 0, differ = 0;
  for (size_t i = 0; i < one.tracks.size(); ++i) {
    REQUIRE(one.tracks[i].name == two.tracks[i].name);
    REQUIRE(one.tracks[i].character == two.tracks[i].character);
    REQUIRE(one.tracks[i].keys.size() == two.tracks[i].keys.size());
    for (size_t k = 0; k < one.tracks[i].keys.size(); ++k) {
      const WalkKey &a = one.tracks[i].keys[k], &b = two.tracks[i].keys[k];
      ++keys;
      const Quat qa = one.tracks[i].Rotation(k), qb = two.tracks[i].Rotation(k);
      differ +=
          !(a.frame == b.frame && a.phase == b.phase && a.position == b.position &&
            a.normal == b.normal && qa.x == qb.x && qa.y == qb.y && qa.z == qb.z && qa.w == qb.w);
    }
  }
  CHECK(keys > 2100 * 10);
  CHECK(differ == 0);
  GenerateOptions bad;
  bad.threads = 0;
  Terrain t = LoadTerrain(MakeFlat(10, 0.1, 0), 0.1);
  Walk w;
  std::string error;
  CHECK(GenerateWalk(*t.session, t.handle, c, bad, &w, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("threads"));
}

TEST_CASE(
    "A crowd on rocks (raised arcs, refused footholds, stops) is the same on one thread, "
    "on two, and walked in passes",
    "[steps][generator][crowd]") {
  // 600 hexapods 5 cm apart on data/terrain/rocks.pts (8 cm samples): enough characters for the
  // per-character passes to split; some arcs need raising (their characters finish in a later
  // round of arc checks) and some characters stop.
  Character c = LoadShipped("hexapod");
  c.max_rise = 0.03;  // so that some characters stop at ridges
  const RawSamples rocks = LoadShippedTerrain("rocks");
  GenerateOptions o;
  o.steps = 30;
  o.crowd = 600;
  o.crowd_spacing = 0.05;
  std::vector<std::pair<int, int>> progress;
  auto run = [&](int threads, int per_pass) {
    Terrain t = LoadTerrain(rocks, 0.08);
    o.threads = threads;
    o.characters_per_pass = per_pass;
    progress.clear();
    o.progress = [&progress](int done, int total) { progress.emplace_back(done, total); };
    return Generate(t, c, o);
  };
  const Walk one = run(1, -1), two = run(2, -1);
  // 5 passes of 128 characters, the last one short; a pass ends early once all its characters
  // have stopped.
  const Walk passes = run(2, 128);
  REQUIRE(!progress.empty());
  CHECK(progress.back().first == progress.back().second);
  CHECK(progress.back().second == 5 * o.steps);
  for (size_t i = 1; i < progress.size(); ++i) CHECK(progress[i].first >= progress[i - 1].first);
  CHECK_THAT(one.stopped, Catch::Contains("more characters stopped"));
  size_t raised = 0;
  for (const Walk* other : {&two, &passes}) {
    CHECK(one.stopped == other->stopped);
    REQUIRE(one.tracks.size() == other->tracks.size());
    size_t differ = 0;
    for (size_t i = 0; i < one.tracks.size(); ++i) {
      const auto &ka = one.tracks[i].keys, &kb = other->tracks[i].keys;
      REQUIRE(ka.size() == kb.size());
      for (size_t k = 0; k < ka.size(); ++k) {
        differ += !(ka[k].frame == kb[k].frame && ka[k].phase == kb[k].phase &&
                    ka[k].position == kb[k].position && ka[k].normal == kb[k].normal &&
                    one.tracks[i].Rotation(k).x == other->tracks[i].Rotation(k).x &&
                    one.tracks[i].Rotation(k).w == other->tracks[i].Rotation(k).w);
        // A raised arc: its mid key more than step_height above the chord's midpoint.
        if (ka[k].phase == KeyPhase::kMid)
          raised += Distance(ka[k].position, (ka[k - 1].position + ka[k + 1].position) * 0.5) >
                    1.01 * c.step_height;
      }
    }
    CHECK(differ == 0);
  }
  CHECK(raised > 0);
  Terrain t = LoadTerrain(rocks, 0.08);
  CheckWalk(t, c, o, passes);
}

TEST_CASE("Bad options are refused with a message", "[steps][generator]") {
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(10, 0.1, 0), 0.1);
  Walk w;
  std::string error;
  GenerateOptions o;
  o.heading = {0, 0, 0};
  CHECK(GenerateWalk(*t.session, t.handle, c, o, &w, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("heading"));
  o = GenerateOptions{};
  o.up = {0, std::nan(""), 0};
  CHECK(GenerateWalk(*t.session, t.handle, c, o, &w, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("up"));
  o = GenerateOptions{};
  CHECK(GenerateWalk(*t.session, t.handle + 99, c, o, &w, &error) == Status::kUnknownTerrain);
  CHECK_THAT(error, Catch::Contains("handle"));
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

namespace {

// Real data from ../shared/data: Keenan Crane's Spot (public domain), resampled by
// footfall::import at `spacing` / `scale` and scaled by `scale`; none when the data is missing
// outside CI (a warning; in CI a failure).
std::optional<Terrain> ScaledSpot(double scale, double spacing) {
  const std::string path = FOOTFALL_SOURCE_DIR "/../shared/data/terrain/mesh_spot_triangulated.obj";
  std::ifstream probe(path);
  if (!probe) {
    if (std::getenv("CI")) FAIL("shared data missing in CI: " << path);
    WARN("skipped: shared data not found at " << path << " (CI is unset)");
    return std::nullopt;
  }
  TerrainLoadOptions load;
  load.separation = spacing / scale;
  RawSamples samples;
  std::string error;
  REQUIRE(footfall::LoadTerrain(path, load, &samples, &error) == Status::kOk);
  for (Vec3& p : samples.points) p = p * scale;
  return test::LoadTerrain(samples, spacing);
}

}  // namespace

TEST_CASE("A multiped walks over the Spot mesh, a closed surface with overhangs",
          "[steps][generator][shared-data]") {
  // Real data from ../shared/data: Keenan Crane's Spot (public domain), resampled by
  // footfall::import and scaled by 2 to a 3.4 m cow for a 30 cm insect.
  const Character c = LoadShipped("hexapod");
  std::optional<Terrain> spot = ScaledSpot(2, c.step_length / 10);
  if (!spot) return;
  Terrain& t = *spot;
  GenerateOptions o;
  o.has_start = true;
  o.start = {0, 1.4, -0.2};  // on the back
  o.heading = {0, 0, -1};    // toward the tail, over it and under the belly
  o.steps = 60;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CheckWalk(t, c, o, w);
  CHECK(StepsDone(w) >= 30);
  // It went over the rump: the body turned past vertical at some point.
  double most_down = 1;
  for (const Quat& q : Body(w).rotations) most_down = std::min(most_down, BodyUp(q).y);
  CHECK(most_down < 0);
}

TEST_CASE("A goal on the Spot mesh's nose is reached by a multiped standing around it",
          "[steps][generator][shared-data]") {
  // Real data from ../shared/data: Spot scaled by 3. The octopod's feet stand around the nose,
  // so their centroid lies inside it, 7 cm below the goal: the goal was never within its
  // radius (5 cm) of the ground, and the octopod turned about it until it stopped.
  const Character c = LoadShipped("octopod");
  std::optional<Terrain> spot = ScaledSpot(3, 0.03);
  if (!spot) return;
  Terrain& t = *spot;
  GenerateOptions o;
  const Vec3 goal{0.0069, -0.221, 3.144};
  o.path.push_back(goal);
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CheckWalk(t, c, o, w);
  CHECK(Distance(Body(w).keys.back().position, goal) < c.step_length);
}

TEST_CASE("The shipped quadruped walks up and down a stair mesh, its body along the flight",
          "[steps][generator]") {
  // Ten steps of 0.18 x 0.28 m (33 degrees) between a floor and a landing, sampled with flat
  // normals at a quarter and at 0.15 of the quadruped's step, five seeds each; its reach as
  // shipped (0.8). The body's up is the normal of the plane of its feet, so on the flight it
  // leans with the slope and the hind feet stay within reach, and its feet's frame lies halfway
  // to the treads', so steps lead up the flight, not into its risers; and its longer and
  // aimed-down retries reach a full step, so a foot whose target locator caught on a nose
  // reaches the tread below. With the feet's averaged normal alone none of these twenty walks
  // got past the fourth step (hind feet 0.82 to 0.94 from the body, or footholds on risers);
  // with the plane but short retries 9 of 10 reached the landing and 4 of 10 the floor; now 9
  // and 8.
  const Character c = LoadShipped("quadruped");
  const int steps = 10;
  const double rise = 0.18, run = 0.28, top = steps * rise, end = steps * run, width = 2;
  TriangleMesh flight;
  auto quad = [&flight](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const uint32_t i = static_cast<uint32_t>(flight.vertices.size());
    flight.vertices.insert(flight.vertices.end(), {a, b, c, d});
    flight.triangles.push_back({i, i + 1, i + 2});
    flight.triangles.push_back({i, i + 2, i + 3});
  };
  quad({0, 0, -3}, {0, 0, 0}, {width, 0, 0}, {width, 0, -3});
  for (int k = 0; k < steps; ++k) {
    const double y0 = k * rise, y1 = y0 + rise, z = k * run;
    quad({0, y0, z}, {0, y1, z}, {width, y1, z}, {width, y0, z});              // riser, -z
    quad({0, y1, z}, {0, y1, z + run}, {width, y1, z + run}, {width, y1, z});  // tread, +y
  }
  quad({0, top, end}, {0, top, end + 3}, {width, top, end + 3}, {width, top, end});
  int to_the_landing = 0, to_the_floor = 0;
  double lean = 0;  // the largest lean back of the body halfway up a flight climbed
  for (const double separation : {0.25 * c.step_length, 0.15 * c.step_length}) {
    for (const uint64_t seed : {1, 2, 3, 4, 5}) {
      RawSamples stairs;
      MeshSampleOptions mo;
      mo.separation = separation;
      mo.smooth_normals = false;
      mo.seed = seed;
      REQUIRE(SampleMesh(flight, mo, &stairs, nullptr) == Status::kOk);
      // Neighbouring samples lie at least 2/3 of the separation apart; CheckWalk's clearance
      // (the distance to the nearest sample less twice that) stays within what the sampling
      // guarantees (every surface point within one separation of a sample).
      Terrain t = LoadTerrain(stairs, separation * 2 / 3);
      for (const bool up : {true, false}) {
        GenerateOptions o;
        o.has_start = true;
        o.start = up ? Vec3{1, 0, -1} : Vec3{1, top, end + 1};
        o.heading = {0, 0, up ? 1.0 : -1.0};
        o.steps = 80;
        const Walk w = Generate(t, c, o);
        INFO(separation << " seed " << seed << (up ? " up: " : " down: ") << w.stopped);
        CheckWalk(t, c, o, w);
        auto depth = [&](const Vec3& p) { return FlightDepth(p, steps, rise, run, rise); };
        CHECK(DeepestSwing(w, depth) <= separation);
        double highest = -1, lowest = 10;
        for (const WalkTrack& track : w.tracks) {
          if (track.kind != TrackKind::kFoot) continue;
          for (const WalkKey& k : track.keys) {
            highest = std::max(highest, k.position.y), lowest = std::min(lowest, k.position.y);
          }
        }
        if (up && highest > top - 0.01) {
          ++to_the_landing;
          const WalkTrack& body = Body(w);
          for (size_t i = 0; i < body.keys.size(); ++i) {
            const double z = body.keys[i].position.z;
            if (z > 0.35 * end && z < 0.65 * end)
              lean = std::max(lean, -BodyUp(body.rotations[i]).z);
          }
        }
        if (!up && lowest < 0.01) ++to_the_floor;
      }
    }
  }
  CHECK(to_the_landing >= 9);
  CHECK(to_the_floor >= 8);
  // Halfway up, the body leans back with the flight (33 degrees), far more than a tread's
  // normal (0) would make it.
  CHECK(lean > std::sin(20 * kPi / 180));
}

namespace {

// 60 steps of a shipped insect from (0.75, 0, 0.6) along +z toward a FloorWithBlock's block at
// z = 1, checked by CheckWalk.
Walk InsectTowardBlock(Terrain& t, const std::string& name) {
  const Character c = LoadShipped(name);
  GenerateOptions o;
  o.has_start = true;
  o.start = {0.75, 0, 0.6};
  o.steps = 60;
  const Walk w = Generate(t, c, o);
  INFO(name << ": " << w.stopped);
  CheckWalk(t, c, o, w);
  return w;
}

}  // namespace

TEST_CASE("Insects before a wall thinner than their step stop there, no swing passing through it",
          "[steps][generator]") {
  // A floor (y = 0, z from 0 to 2) cut by a wall 2 cm thick and 30 cm tall at z = 1: its two
  // faces and its top, sampled 1 cm apart. The footholds ahead of a foot at the wall's foot lie
  // on the floor behind it, 2 cm of wall between: arcs were checked at seven points about 2 cm
  // apart, and some passed through the wall's middle (so the insects "crossed" it). Arcs are now
  // checked at points no farther apart than about two sample spacings: no arc reaches the floor
  // behind, and the walk stops with the keys so far.
  const double s = 0.01;
  Terrain t = LoadTerrain(FloorWithBlock(s, 150, 200, 1.0, 1.02, 0.3, 30, false), s);
  auto depth = [](const Vec3& p) { return FloorOrBlockDepth(p, 1.0, 1.02, 0.3); };
  for (const std::string name : {"hexapod", "octopod"}) {
    const Walk w = InsectTowardBlock(t, name);
    INFO(name << ": " << w.stopped);
    CHECK_THAT(w.stopped, Catch::Contains("cannot clear the terrain"));
    CHECK(StepsDone(w) >= 3);
    CHECK(DeepestSwing(w, depth) == 0);
    for (const WalkTrack& track : w.tracks)
      if (track.kind == TrackKind::kFoot) CHECK(track.keys.back().position.z <= 1.0);
  }
}

TEST_CASE("Insects climb a box, cross its top and climb down its far side", "[steps][generator]") {
  // A floor (y = 0, z from 0 to 2) with a box 30 cm tall and 30 cm deep across it at z = 1,
  // sampled 1 cm apart: its front face, its top and its back face.
  const double s = 0.01, depth = 0.3;
  Terrain t = LoadTerrain(FloorWithBlock(s, 150, 200, 1.0, 1.0 + depth, 0.3, 30, false), s);
  auto inside = [&](const Vec3& p) { return FloorOrBlockDepth(p, 1.0, 1.0 + depth, 0.3); };
  for (const std::string name : {"hexapod", "octopod"}) {
    const Walk w = InsectTowardBlock(t, name);
    INFO(name << ": " << w.stopped);
    CHECK(DeepestSwing(w, inside) <= s);
    // The body went over the top and every foot ends on the floor beyond the box.
    double highest = 0;
    for (const WalkKey& k : Body(w).keys) highest = std::max(highest, k.position.y);
    CHECK(highest > 0.3);
    for (const WalkTrack& track : w.tracks) {
      if (track.kind != TrackKind::kFoot) continue;
      CHECK(track.keys.back().position.z > 1.0 + depth + 0.05);
      CHECK(track.keys.back().position.y == Approx(0).margin(1e-6));
    }
  }
}

TEST_CASE("Long strides over finely sampled stairs keep their swings out of the noses",
          "[steps][generator]") {
  // Bipeds of 1.8 and 3 m strides on stairs sampled every 2 cm (rise 20 cm, run 30 cm)
  // after 2 m of floor, each riser's samples reaching up to its nose: each stride spans several
  // treads and lands in a tread's inner corner, under the next nose. Seven check points let the
  // straight stretch into that corner pass 7.5 cm through the nose; the points are now no
  // farther apart than about two sample spacings. And among that many, some lie high over a
  // nose just behind its riser's plane, whose top sample is nearest: taken as below the
  // terrain, they stopped the larger biped at its second step down.
  const double rise = 0.2, run = 0.3, spacing = 0.02, floor = 2;
  const int steps = 20;
  RawSamples stairs;
  for (int i = 0; i <= 100; ++i) {
    const double x = i * spacing;
    for (int k = 0; k <= 100; ++k) stairs.push_back({x, 0, k * spacing}, {0, 1, 0});
    for (int n = 0; n < steps; ++n) {
      const double z0 = floor + n * run;
      for (int j = 1; j <= 10; ++j) stairs.push_back({x, n * rise + j * spacing, z0}, {0, 0, -1});
      for (int k = 1; k <= 15; ++k)
        stairs.push_back({x, (n + 1) * rise, z0 + k * spacing}, {0, 1, 0});
    }
  }
  Terrain t = LoadTerrain(stairs, spacing);
  auto depth = [&](const Vec3& p) {
    return FlightDepth(p - Vec3{0, 0, floor}, steps, rise, run, rise);
  };
  struct Size {
    double rest, step_length, step_height, body_height, reach, max_rise;
  };
  for (const Size& z : {Size{0.2, 1.8, 0.4, 3.0, 3.6, 0.9}, Size{0.5, 3.0, 0.6, 4.0, 6.0, 1.0}}) {
    Character c = LoadShipped("biped");
    c.feet[0].rest = {z.rest, 0, 0}, c.feet[1].rest = {-z.rest, 0, 0};
    c.step_length = z.step_length, c.step_height = z.step_height;
    c.body_height = z.body_height, c.reach = z.reach, c.max_rise = z.max_rise;
    c.frames_per_step = 16;
    for (const bool up : {true, false}) {
      GenerateOptions o;
      o.has_start = true;
      o.start = up ? Vec3{1, 0, 0.3} : Vec3{1, rise * steps, floor + run * steps - 0.1};
      o.heading = {0, 0, up ? 1.0 : -1.0};
      o.steps = 6;
      const Walk w = Generate(t, c, o);
      INFO(z.step_length << (up ? " up: " : " down: ") << w.stopped);
      CHECK(w.stopped.empty());
      CHECK(DeepestSwing(w, depth) <= spacing);
    }
  }
}

namespace {

// A profile in the plane x = 0 extruded 1.5 m along +x, as a modelling package exports it: each
// profile point's two vertices shared by the faces on either side of its edge.
TriangleMesh Extruded(const std::vector<Vec3>& profile) {
  TriangleMesh mesh;
  for (const Vec3& p : profile) {
    mesh.vertices.push_back(p);
    mesh.vertices.push_back(p + Vec3{1.5, 0, 0});
  }
  for (uint32_t k = 0; k + 1 < profile.size(); ++k) {
    const uint32_t a = 2 * k, b = a + 1, c = a + 2, d = a + 3;
    mesh.triangles.push_back({a, c, d});
    mesh.triangles.push_back({a, d, b});
  }
  return mesh;
}

// `mesh` sampled as `footfall generate` samples it for `c` (a quarter step, smooth normals).
Terrain SampledFor(const TriangleMesh& mesh, const Character& c, uint64_t seed) {
  RawSamples samples;
  MeshSampleOptions mo;
  mo.separation = kSeparationPerStep * c.step_length;
  mo.seed = seed;
  REQUIRE(SampleMesh(mesh, mo, &samples, nullptr) == Status::kOk);
  // Neighbouring samples lie at least 2/3 of the separation apart (CheckWalk's spacing).
  return LoadTerrain(samples, mo.separation * 2 / 3);
}

}  // namespace

TEST_CASE("Insects climb walls of a modelled mesh, whose edges keep their faces' normals",
          "[steps][generator]") {
  // A floor (z < 0), a wall (z = 0, facing -z) and its top, 1.5 m wide, as a modelling package
  // exports them (Extruded), sampled as `footfall generate` samples a mesh for an insect, six
  // seeds per wall height. Smooth normals stop at the wall's 90-degree edges
  // (kDefaultCreaseAngleDeg): interpolated from plain vertex normals instead, the wall's and
  // the floor's normals leaned up to 45 degrees toward each other, all the way across the
  // wall: 5 of 6 hexapods and 1 of 6 octopods got over the 1 m wall, none over 0.5 or 0.3 m.
  for (const double height : {1.0, 0.5, 0.3}) {
    const TriangleMesh wall = Extruded({{0, 0, -1}, {0, 0, 0}, {0, height, 0}, {0, height, 1.5}});
    for (const std::string name : {"hexapod", "octopod"}) {
      const Character c = LoadShipped(name);
      int over = 0;
      for (const uint64_t seed : {1, 2, 3, 4, 5, 6}) {
        Terrain t = SampledFor(wall, c, seed);
        GenerateOptions o;
        o.has_start = true;
        o.start = {0.75, 0, -0.5};
        o.steps = 100;
        const Walk w = Generate(t, c, o);
        INFO(name << " over " << height << " m, seed " << seed << ": " << w.stopped);
        CheckWalk(t, c, o, w);
        const WalkKey& last = Body(w).keys.back();
        if (last.position.y > height && last.position.z > 0.2) ++over;
      }
      INFO(name << " over " << height << " m: " << over << " of 6");
      CHECK(over >= 5);
    }
  }
}

TEST_CASE("Insects descend a modelled flight of stairs, a group waiting for a foot left behind",
          "[steps][generator]") {
  // Ten steps of 0.18 x 0.28 m between a floor and a landing, one profile extruded (shared
  // vertices, exact normals: smooth normals stop at the 90-degree edges), sampled for each
  // insect at a quarter step, six seeds. Going down a riser three to four times their body
  // height, the front feet drop to the tread below while a hind foot still stands on the tread
  // above, and every try of the stepping group would leave it beyond reach: then the group
  // waits, feet planted, and the next group, that foot's, steps on. (Without the wait none of the
  // six hexapods and 3 of the six octopods reached the floor; with it 4 and 5.)
  const int steps = 10;
  const double rise = 0.18, run = 0.28;
  std::vector<Vec3> profile = {{0, 0, -1}, {0, 0, 0}};
  for (int k = 0; k < steps; ++k) {
    profile.push_back({0, (k + 1) * rise, k * run});
    profile.push_back({0, (k + 1) * rise, (k + 1) * run});
  }
  profile.push_back({0, steps * rise, steps * run + 1.5});
  const TriangleMesh flight = Extruded(profile);
  for (const std::string name : {"hexapod", "octopod"}) {
    const Character c = LoadShipped(name);
    int down = 0, waits = 0;
    for (const uint64_t seed : {1, 2, 3, 4, 5, 6}) {
      Terrain t = SampledFor(flight, c, seed);
      GenerateOptions o;
      o.has_start = true;
      o.start = {0.75, steps * rise, steps * run + 0.7};
      o.heading = {0, 0, -1};
      o.steps = 250;
      const Walk w = Generate(t, c, o);
      INFO(name << " seed " << seed << ": " << w.stopped);
      CheckWalk(t, c, o, w);
      if (Body(w).keys.back().position.y < 0.5 * rise) ++down;
      // A wait: a step in which no foot moves and the body holds (CheckWalk checks the rest).
      const auto& body = Body(w).keys;
      for (size_t k = 1; k < body.size(); ++k) waits += body[k].position == body[k - 1].position;
    }
    INFO(name << ": " << down << " of 6 reached the floor, " << waits << " waits");
    CHECK(down >= (name == "hexapod" ? 3 : 4));
    CHECK(waits > 0);
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

namespace footfall::test {

TEST_CASE("Options no walk can follow are refused with the reason", "[steps][generator]") {
  Terrain t = LoadTerrain(MakeFlat(40, 0.05, 0), 0.05);
  Walk w;
  std::string error;
  SECTION("a heading along the up where the character starts") {
    // The insect's up is the floor's normal: straight up gives no direction on the ground (it
    // used to fall back to another direction silently).
    GenerateOptions o;
    o.heading = {0, 2, 0};
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) ==
          Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("the heading (0.0000, 1.0000, 0.0000) is along the up"));
    // A few degrees off the up, what is left on the ground is noise or the ground's tilt (the
    // default +Z heading on a Z-up terrain walked an insect downhill): refused too.
    const double rad = 3.14159265358979323846 / 180;
    o.heading = {std::sin(8 * rad), std::cos(8 * rad), 0};
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) ==
          Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("within 10 deg of it"));
    // Past the threshold the heading's ground part is the direction walked.
    o.heading = {std::sin(12 * rad), std::cos(12 * rad), 0};
    REQUIRE(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) ==
            Status::kOk);
    const WalkTrack& body = w.tracks.back();
    REQUIRE(body.keys.size() > 2);
    const Vec3 moved = body.keys.back().position - body.keys.front().position;
    CHECK(moved.x > 0.1);
    CHECK(std::fabs(moved.z) < 0.25 * moved.x);
    // With a path, the heading is not used.
    o.path = {{1.5, 0, 1.5}};
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) == Status::kOk);
  }
  SECTION("a start frame or fps beyond the command line's bounds, from any caller") {
    GenerateOptions o;
    o.start_frame = 1e300;  // every key landed on one frame
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("biped"), o, &w, &error) ==
          Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("the start frame within +-1e+09"));
    o.start_frame = 1;
    o.fps = 1e7;
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("biped"), o, &w, &error) ==
          Status::kInvalidArgument);
  }
}

}  // namespace footfall::test
