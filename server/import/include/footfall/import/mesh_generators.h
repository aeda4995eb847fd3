// Synthetic triangle meshes with known geometry, for `footfall terrain make`, tests and
// benchmarks. Y is up; lengths in world units (wu); all deterministic for a given seed. Resample
// them with SampleMesh (mesh_sampler.h).
#pragma once

#include <cstdint>
#include <vector>

#include "footfall/import/triangle_mesh.h"

namespace footfall {

// Blocks of unit cubes on the floor y = 0: an nx x nz grid of unit columns (x in [0, nx],
// z in [0, nz]) whose integer heights 0..max_height are drawn from the seed in clustered piles.
// Every exposed unit face (tops, sides, the floor between piles) is its own pair of triangles
// facing out of the solid; no shared vertices between faces, so smooth normals stay flat.
TriangleMesh MakeBlocksMesh(int nx, int nz, int max_height, uint64_t seed);

// A walkway `width` wide (x in [0, width]) along +z: a flat approach `length` long, then one
// segment per entry of `slopes_deg` rising (or falling, if negative) at that angle over a
// horizontal run of `length`, then a flat landing `length` long. Normals face up.
TriangleMesh MakeRampsMesh(const std::vector<double>& slopes_deg, double length, double width);

// Rocky ground: an (n + 1) x (n + 1) vertex height field over [0, n * cell]^2 with ridged
// multi-octave value noise of peak-to-trough height about `amplitude`.
TriangleMesh MakeRocksMesh(int n, double cell, double amplitude, uint64_t seed);

// A flight of `steps` stairs rising along +z, `width` across (x in [0, width]): a floor at
// y = 0 from z = -3 * run to 0, then treads (facing +y) `rise` above each other and `run` deep,
// with risers (facing -z) between them. Every face has its own vertices, so smooth normals stay
// flat and a stair's nose is a sharp edge; the sides are open.
TriangleMesh MakeStairsMesh(int steps, double rise, double run, double width);

// A sphere of `radius` about `centre`: an icosahedron subdivided `subdivisions` times
// (20 * 4^subdivisions triangles), vertices on the sphere, faces outward.
TriangleMesh MakeSphereMesh(const Vec3& centre, double radius, int subdivisions);

}  // namespace footfall
