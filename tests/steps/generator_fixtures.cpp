#include "generator_fixtures.h"

#include "footfall/import/terrain_generators.h"

namespace footfall::test {

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

GenerateOptions PathOptions(const Vec3& start, const std::vector<Vec3>& path, int steps) {
  GenerateOptions o = StartOptions(start, steps);
  o.path = path;
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

}  // namespace footfall::test
