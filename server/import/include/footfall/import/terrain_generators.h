// Synthetic terrains with exactly known geometry, for tests, benchmarks and `footfall terrain
// make`. All are deterministic for a given seed. Sample spacing is `spacing` world units; Y is up.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "footfall/import/mesh_sampler.h"
#include "footfall/terrain/samples.h"

namespace footfall {

// A height field y = amplitude * smooth noise over [0, nx) x [0, nz) samples, normals from the
// surface gradient.
RawSamples MakeHeightField(int nx, int nz, double spacing, double amplitude, uint64_t seed);

// The same noise in world units, one noise unit every kHillsUnit: hills whose relief is the
// same whatever the spacing they are sampled at (n x n samples from the origin). MakeHills at
// a spacing of kHillsUnit is MakeHeightField's field.
constexpr double kHillsUnit = 1.0;
RawSamples MakeHills(int n, double spacing, double amplitude, uint64_t seed);

// Samples spread evenly over a sphere (Fibonacci lattice), normals pointing outwards.
RawSamples MakeSphere(int count, const Vec3& centre, double radius);

// A staircase along +Z: `steps` treads of the given run, `width` wide (X), the first on the
// ground (y = 0) and each next one `rise` higher (so steps - 1 risers, the top tread at
// (steps - 1) * rise); treads and risers sampled at `spacing`, normals +Y on treads and, on
// risers, -Z (a positive rise) or +Z (a negative rise: stairs going down along +Z).
RawSamples MakeStairs(int steps, double rise, double run, double width, double spacing);

// A closed room: floor (normal +Y), four walls (normals inward) and a ceiling (normal -Y), size
// (sx, sy, sz) from the origin.
RawSamples MakeRoom(const Vec3& size, double spacing);

// A flat square of n x n samples at height y, normal +Y.
RawSamples MakeFlat(int n, double spacing, double y);

// A planar ramp rising along +Z at `slope_deg` degrees, nx x nz samples (spacing along the
// surface), normals perpendicular to it.
RawSamples MakeRamp(int nx, int nz, double spacing, double slope_deg);

// The meshes of mesh_generators.h resampled at separation `spacing` (mesh_sampler.h) with the
// given seed: blocks of unit cubes (flat normals), ramps of the given slopes joined by flat
// landings (flat normals), rocky noise over a square `size` wu wide (smooth normals). Empty when
// the sampler refuses (too many samples for its area, non-finite vertices), or rocks that reach
// beyond kMaxCoordinate (refused before sampling): *error, when given,
// then says why. The sampler's estimate refuses more than `max_samples` samples before any is
// made (as MeshSampleOptions::max_samples).
RawSamples MakeBlocks(int nx, int nz, int max_height, double spacing, uint64_t seed,
                      std::string* error = nullptr,
                      size_t max_samples = MeshSampleOptions{}.max_samples);
RawSamples MakeRamps(const std::vector<double>& slopes_deg, double length, double width,
                     double spacing, std::string* error = nullptr,
                     size_t max_samples = MeshSampleOptions{}.max_samples);
RawSamples MakeRocks(double size, double amplitude, double spacing, uint64_t seed,
                     std::string* error = nullptr,
                     size_t max_samples = MeshSampleOptions{}.max_samples);

}  // namespace footfall
