// Terrain set-up for a walk: a mesh or height map resampled finely enough for a character's
// steps, over the part of it the walk can reach.
//
// A file's own spacing (a DEM's metre, a mesh's mean edge) is often coarser than a character's
// step: a biped looks for a foothold within 0.35 m of where it aims, an insect within 6 cm.
// PrepareWalkTerrain resamples the surface at kSeparationPerStep (generator.h) of the
// character's step, but only within a box around the start that the walk cannot leave
// (MaxStepTravel per step, the feet's rest spread, the crowd's grid, the reach, the swing
// arcs' height and, for a start that may move, StartSearchRadius), so that a small character on a
// large terrain costs what its walk covers, not the whole file.
#pragma once

#include <string>

#include "footfall/import/terrain_loader.h"
#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"

namespace footfall {

// At most this many samples for a character, whatever the load's budget: the sampler needs
// several hundred bytes per sample while it works.
constexpr size_t kMaxWalkSamples = 2000000;
// A surface that those samples would cover only at a separation more than this many times
// kSeparationPerStep of the step (a whole step: samples at least 2/3 of a step apart, while a
// character looks for each foothold within half a step; the shipped insects resampled so
// stopped within their first steps on gentle bumps, and walked at 3 times) is refused before it
// is resampled (kLimitExceeded, saying what to give instead); a coarser one within it is
// resampled at what fits (WalkTerrain::report says at what).
constexpr double kMaxWalkCoarsening = 4;

struct WalkTerrain {
  RawSamples samples;
  TerrainLoadReport report;  // what was read and how it was resampled
  // Where the walk starts: options.start, or the surface point nearest the centre of the top of
  // the terrain's bounds along options.up (GenerateWalk's default, found on the surface before
  // cropping; the caller lets it move, GenerateOptions::start_may_move, within the box); world
  // space, not yet snapped to a sample.
  Vec3 start;
  double wanted_separation = 0;  // kSeparationPerStep * step_length [Units: wu]
  // The box the surface was cropped to (triangles meeting it were kept); false: all of it.
  bool cropped = false;
  Vec3 region_min, region_max;
  // With a path and no step count the box bounds the walk only approximately (the path's box
  // widened by a few steps): a walk stopping near its edge may have met the edge.
  bool region_is_bound = true;
};

// When `report`'s resampling came out coarser than `wanted` (kSeparationPerStep of the step)
// and than the file's own spacing, as the kMaxWalkSamples limit makes it: "not finer than S (K
// times a quarter of the step): the surface would need more samples than the 2000000 a walk's
// terrain may have, and the character may miss footholds"; else "".
std::string CoarserThanStepsNote(const TerrainLoadReport& report, double wanted);

// Reads the mesh or height map at `path` (load: its frame flags and sample budget; its
// separation must be 0) and resamples it for `character` walking as `options` say. Errors as
// LoadTerrain; kInvalidArgument for a point file or a separation set; kLimitExceeded for a
// surface too large to resample finely enough for the character (kMaxWalkCoarsening).
Status PrepareWalkTerrain(const std::string& path, const TerrainLoadOptions& load,
                          const Character& character, const GenerateOptions& options,
                          WalkTerrain* out, std::string* error);

}  // namespace footfall
