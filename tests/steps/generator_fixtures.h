// Fixtures of the step generator tests: terrains and walks used across their files, and
// measures of a walk (its body's frame, how deep its swings pass into a known solid).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/terrain/vec3.h"
#include "walk_checks.h"

namespace footfall::test {

inline constexpr double kPi = 3.14159265358979323846;

// Terrain sizes follow the character: a biped's terrain is ~6 times an insect's.
double Scale(const Character& c);

// The body's heading (its +Z) and up (its +Y) under rotation q.
Vec3 BodyForward(const Quat& q);
Vec3 BodyUp(const Quat& q);

// The steps a walk took: its body's keys less the start's.
size_t StepsDone(const Walk& w);

// The walk's (first) body track; FAILs when there is none.
const WalkTrack& Body(const Walk& w);

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
double FlightDepth(const Vec3& p, int steps, double rise, double run, double first_top);

// A floor (y = 0) of (nx + 1) x (nz + 1) samples `s` apart, cut across by a block from z0 to z1,
// `height` tall: its faces (-z at z0, +z at z1) sampled in `rows` rows up to its top, and its
// top on the floor's lattice between them (with its edges when `edges_on_top`, else the faces'
// top rows hold them).
RawSamples FloorWithBlock(double s, int nx, int nz, double z0, double z1, double height, int rows,
                          bool edges_on_top);

// How deep p lies below that floor or in that block (positive inside).
double FloorOrBlockDepth(const Vec3& p, double z0, double z1, double height);

// Walks 12 steps from `start` along +Z (`forward`) or -Z and checks the walk: no stop, every
// invariant of CheckWalk, and the body rising by more than `rise` (a negative `rise`: falling by
// more than -rise).
Walk WalkTwelveSteps(Terrain& t, const Character& c, const Vec3& start, bool forward, double rise);

// `steps` steps of c from (5, 0, 2) along +Z on a flat floor 10 m wide: not stopped, and every
// invariant of CheckWalk held.
Walk CheckedWalkOnFlat(const Character& c, int steps);

// One character starting at `start`, walking `steps` steps.
GenerateOptions StartOptions(const Vec3& start, int steps);

// One character starting at `start`, following `path`, for at most `steps` steps.
GenerateOptions PathOptions(const Vec3& start, const std::vector<Vec3>& path, int steps);

// A flat square `side` wide at y = 0, sampled at a tenth of c's step, loaded.
Terrain FlatFor(const Character& c, double side);

// A crowd of `crowd` characters `spacing` apart around `start`, walking `steps` steps.
GenerateOptions CrowdOptions(const Vec3& start, int steps, int crowd, double spacing);

}  // namespace footfall::test
