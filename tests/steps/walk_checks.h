// Shared helpers of the step generator tests: shipped characters, terrains scaled to a
// character, and the invariants every generated walk must satisfy.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "footfall/client/terrain_session.h"
#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/walk.h"

namespace footfall::test {

const std::vector<std::string>& ShippedCharacters();     // "biped", "quadruped", ...
Character LoadShipped(const std::string& name);          // from data/characters (REQUIREs success)
RawSamples LoadShippedTerrain(const std::string& name);  // data/terrain/NAME.pts (REQUIREs success)

// A terrain loaded into a fresh embedded session.
struct Terrain {
  std::unique_ptr<TerrainSession> session;
  TerrainHandle handle = 0;
  RawSamples samples;
  double spacing = 0;  // distance between neighbouring samples [Units: wu]
};
Terrain LoadTerrain(const RawSamples& samples, double spacing);

// Generates a walk (REQUIREs kOk).
Walk Generate(Terrain& t, const Character& c, const GenerateOptions& o);

// The foot position of a track at `frame` (held between keys, linear between a step's keys).
Vec3 FootAt(const WalkTrack& track, double frame);

// Checks every invariant with Catch assertions:
//  - frames increase along every track, and every track has keys;
//  - every start and end key lies on a terrain sample (snapping it returns the same point and
//    normal);
//  - a planted foot does not move between its end key and its next start key;
//  - the swing arc start-mid-end clears the terrain: at the generator's check points
//    (s = 1/8 .. 7/8 of the polyline) by a quarter of the nominal clearance, and nowhere (s =
//    0.1 .. 0.9) by more than one sample spacing below it;
//  - every body key sits body_height along its up above the centroid of the feet at that frame,
//    and every foot is within reach of it;
//  - the feet step in the declared gait order, one group per step, a group waiting (no foot
//    lifting, the body still) at most a cycle less one in a row, unless its character turns on
//    the spot toward a waypoint (its body turning during the run of waits).
void CheckWalk(Terrain& t, const Character& c, const GenerateOptions& o, const Walk& w);

// Tracks of one character ("" for a single one): feet in file order, then the body.
std::vector<const WalkTrack*> TracksOf(const Walk& w, const std::string& character);

}  // namespace footfall::test
