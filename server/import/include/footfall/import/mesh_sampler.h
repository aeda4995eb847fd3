// Resamples a triangle mesh into terrain samples at a chosen point separation s.
//
// The method, in numbered steps (the code repeats the numbers):
//   1. Candidates: every triangle is split by longest-edge bisection until each piece's centroid
//      lies within s/3 of the piece's corners; each piece's centroid is a candidate. So every point
//      of the surface lies within s/3 of a candidate.
//   2. Candidates are visited in a random order fixed by the seed (a Fisher-Yates shuffle with our
//      own generator, so the order is the same on every platform).
//   3. A candidate is accepted unless an accepted sample lies closer than 2s/3 (a uniform grid of
//      cells of that size answers this). This is maximal Poisson-disk sampling ("blue noise"):
//      samples are at least 2s/3 apart (no clumps), and every candidate lies within 2s/3 of a
//      sample, so every point of the surface lies within s/3 + 2s/3 = s of a sample.
//   4. Each accepted sample gets the face normal (flat) or the barycentric blend of the vertex
//      normals (smooth), falling back to the face normal where the blend is zero or faces away from
//      the face. Samples are returned in triangle order.
// The sample count is close to 1.6 * area / s^2 on smooth surfaces.
//
// What it does not do: it measures distance in 3D, not along the surface, so two sheets closer
// than 2s/3 (a thin wall) share samples; it ignores normals stored in the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "footfall/import/triangle_mesh.h"
#include "footfall/terrain/samples.h"
#include "footfall/terrain/status.h"

namespace footfall {

// The default crease angle of smooth normals (MeshSampleOptions::crease_angle_deg). [Units:
// degrees]
constexpr double kDefaultCreaseAngleDeg = 60;

struct MeshSampleOptions {
  // Point separation s: the farthest any surface point may be from a sample. [Units: wu] [Limit: >
  // 0]
  double separation = 1;
  // Normals interpolated across each triangle from its corners' (true: CornerNormals, smooth
  // across edges gentler than crease_angle_deg) or the face's (false).
  bool smooth_normals = true;
  // Edges whose faces meet at a larger angle stay sharp: each face keeps its own normal up to
  // them. [Units: degrees] 30: a modelling package's usual auto smooth; >= 180: smooth across
  // every edge (plain vertex normals).
  double crease_angle_deg = kDefaultCreaseAngleDeg;
  // Seed of the visiting order; equal seeds give equal samples.
  uint64_t seed = 1;
  // Refuse (kLimitExceeded) when area / s^2 predicts more samples than this.
  size_t max_samples = 20000000;
  // Threads cutting triangles (steps 1 and 4); the samples are the same whatever their number.
  // 0: one per core.
  int threads = 0;
};

struct MeshSampleStats {
  size_t candidates = 0;  // step 1
  size_t samples = 0;     // accepted in step 3
};

// Samples `mesh` (degenerate triangles should be removed first: they get no samples but are
// harmless). Errors: kInvalidArgument (separation not finite and > 0, non-finite vertex, index out
// of range), kLimitExceeded (too many samples for max_samples). *out holds unit normals.
Status SampleMesh(const TriangleMesh& mesh, const MeshSampleOptions& options, RawSamples* out,
                  std::string* error, MeshSampleStats* stats = nullptr);

// A baseline for benchmarks and tests: `count` points drawn uniformly at random on the surface
// (area-weighted triangle choice), with the same normal rule. No spacing guarantee.
void SampleMeshUniform(const TriangleMesh& mesh, size_t count, bool smooth_normals,
                       double crease_angle_deg, uint64_t seed, RawSamples* out);

// The separation used when none is given: the mean edge length of the mesh. [Units: wu]
double DefaultSeparation(const TriangleMesh& mesh);

}  // namespace footfall
