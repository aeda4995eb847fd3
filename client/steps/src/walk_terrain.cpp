#include "footfall/steps/walk_terrain.h"

#include <algorithm>
#include <cmath>

#include "frame_math.h"

namespace footfall {
namespace {

// Swing arcs rise at most this many step heights above their chord (the mid key's height and
// the generator's raises), and their check points snap to the terrain below.
constexpr double kArcStepHeights = 6;
// With a path and no step count, the walk is taken to stay within this many steps' travel of
// the box of its start and waypoints (it turns toward each waypoint as it goes).
constexpr double kPathSlackSteps = 8;

// How far from the start's ground point anything the walk touches can lie, beside the steps
// themselves: the crowd's grid (each character snapped within twice its offset), the feet's
// rest spread (each foot snapped within twice its rest distance), the reach, a step of
// locator lead and the swing arcs' height.
double SpreadAroundStart(const Character& c, const GenerateOptions& o) {
  const int n = std::max(1, o.crowd);
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const int rows = (n + cols - 1) / cols;
  const double spacing = o.crowd_spacing > 0 ? o.crowd_spacing : 2 * c.reach;
  const double crowd = n > 1 ? spacing * std::hypot(0.5 * (cols - 1), 0.5 * (rows - 1)) : 0;
  double rest = 0;
  for (const FootSpec& f : c.feet) rest = std::max(rest, Length(f.rest));
  return 2 * crowd + 2 * rest + c.reach + c.step_length + kArcStepHeights * c.step_height +
         c.max_rise;
}

}  // namespace

Status PrepareWalkTerrain(const std::string& path, const TerrainLoadOptions& load,
                          const Character& character, const GenerateOptions& options,
                          WalkTerrain* out, std::string* error) {
  *out = WalkTerrain{};
  if (load.separation > 0) {
    *error = "PrepareWalkTerrain chooses the separation itself; load the file with it set";
    return Status::kInvalidArgument;
  }
  TriangleMesh mesh;
  Status status = ReadTerrainMesh(path, load, &mesh, error, &out->report);
  if (status != Status::kOk) return status;
  const Vec3 up = steps_detail::NormalizeOr(options.up, Vec3{0, 1, 0});
  Vec3 mesh_lo, mesh_hi;
  MeshBounds(mesh, &mesh_lo, &mesh_hi);
  out->start = NearestSurfacePoint(
      mesh, options.has_start ? options.start : TopCentre(mesh_lo, mesh_hi, up));

  // The box the walk cannot leave: its steps from the start, or, along a path walked to its
  // end, the path's box widened by a few steps.
  // A start that may move (the default one) may stand anywhere within the search radius.
  const bool may_move = !options.has_start || options.start_may_move;
  const double spread =
      SpreadAroundStart(character, options) + (may_move ? StartSearchRadius(character) : 0);
  const double travel = MaxStepTravel(character);
  Vec3 lo = out->start, hi = out->start;
  double widen = 0;
  if (options.steps < 0 && !options.path.empty()) {
    for (const Vec3& p : options.path) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    widen = spread + kPathSlackSteps * travel;
    out->region_is_bound = false;
  } else {
    const int steps = options.steps >= 0 ? options.steps : kDefaultSteps;
    widen = spread + steps * travel;
  }
  out->region_min = lo - Vec3{widen, widen, widen};
  out->region_max = hi + Vec3{widen, widen, widen};
  out->cropped = mesh_lo.x < out->region_min.x || mesh_lo.y < out->region_min.y ||
                 mesh_lo.z < out->region_min.z || mesh_hi.x > out->region_max.x ||
                 mesh_hi.y > out->region_max.y || mesh_hi.z > out->region_max.z;
  if (out->cropped) CropToBox(&mesh, out->region_min, out->region_max);

  TerrainLoadOptions sample = load;
  out->wanted_separation = kSeparationPerStep * character.step_length;
  sample.finest_default = out->wanted_separation;
  sample.max_samples = std::min(load.max_samples, kMaxWalkSamples);
  return ResampleTerrainMesh(path, mesh, sample, &out->samples, error, &out->report);
}

}  // namespace footfall
