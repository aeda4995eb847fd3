// The step generator on meshes: the Spot mesh (a closed surface with overhangs), stair meshes,
// blocks and walls thinner than a step, modelled walls and stairs whose edges keep their faces'
// normals.
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
  // with the plane but short retries 9 of 10 reached the landing and 4 of 10 the floor; then 9
  // and 8; with swing arcs hooked out from a riser (a foot stepping down off a nose), 10 and 9.
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
  CHECK(to_the_landing >= 10);
  CHECK(to_the_floor >= 9);
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
