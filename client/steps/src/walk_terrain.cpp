#include "footfall/steps/walk_terrain.h"

#include <algorithm>
#include <cmath>

#include "footfall/terrain/text_stream.h"
#include "frame_math.h"
#include "step_generator.h"

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

// The error for a surface that the sample budget would resample at `separation`, too coarse
// for the character: the walk would stop at its first steps, wanting footholds.
Status TooCoarse(const std::string& path, const Character& c, const WalkTerrain& t,
                 double separation, double area, std::string* error) {
  steps_detail::Text m(4);
  m << path << ": resampled for " << (c.name.empty() ? "the character" : c.name)
    << " at a quarter of its step (" << t.wanted_separation << ")";
  if (t.cropped) m << " within the box its walk can reach";
  m << ", its " << static_cast<long long>(std::min(9e18, std::ceil(area)))
    << " square units would need about "
    << static_cast<long long>(
           std::min(9e18, std::ceil(1.6 * area / (t.wanted_separation * t.wanted_separation))))
    << " samples, more than the " << kMaxWalkSamples
    << " a walk's terrain may have; at the separation that fits, " << separation
    << " (more than its step), samples lie farther apart than the half step ("
    << 0.5 * c.step_length
    << ") within which the character looks for a foothold, and the walk would stop within its "
       "first steps; "
    << (t.region_is_bound ? "give fewer --steps"
                          : "give --steps, or waypoints nearer the start (the box holds them "
                            "and eight steps around them)")
    << ", or --separation S to resample the whole file at S";
  *error = m.str();
  return Status::kLimitExceeded;
}

}  // namespace

std::string CoarserThanStepsNote(const TerrainLoadReport& report, double wanted) {
  if (!(report.separation > 1.0001 * std::min(wanted, report.file_separation))) return "";
  TextStream o;
  o.precision(4);
  o << "not finer than " << report.separation << " (" << report.separation / wanted
    << " times a quarter of the step): the surface would need more samples than the "
    << kMaxWalkSamples << " a walk's terrain may have, and the character may miss footholds";
  return o.str();
}

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
  // A start given straight above or below the ground (y = 0 under a DEM's hills) is that
  // ground, as the generator takes it (GroundAlongUp): the box goes around it.
  if (options.has_start)
    steps_detail::SettleAlongUp(
        options.start, up, character.step_length, &out->start,
        [&](const Vec3& q, Vec3* next) {
          *next = NearestSurfacePoint(mesh, q);
          return true;
        },
        [](const Vec3& p) { return p; });

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
  // Along a path, the ground the walk follows may climb or fall any height between waypoints
  // (given at y = 0 over a DEM 540 m up, the box stopped 2 m below a bank the path crosses, and
  // the walk stopped at its edge as at a cliff): the box spans the whole surface along up.
  if (!out->region_is_bound) {
    auto along = [](Vec3& v, int axis) -> double& {
      return axis == 0 ? v.x : axis == 1 ? v.y : v.z;
    };
    Vec3 u = up;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::fabs(along(u, axis)) < 1e-12) continue;
      along(out->region_min, axis) = std::min(along(out->region_min, axis), along(mesh_lo, axis));
      along(out->region_max, axis) = std::max(along(out->region_max, axis), along(mesh_hi, axis));
    }
  }

  out->cropped = mesh_lo.x < out->region_min.x || mesh_lo.y < out->region_min.y ||
                 mesh_lo.z < out->region_min.z || mesh_hi.x > out->region_max.x ||
                 mesh_hi.y > out->region_max.y || mesh_hi.z > out->region_max.z;
  if (out->cropped) CropToBox(&mesh, out->region_min, out->region_max);

  TerrainLoadOptions sample = load;
  out->wanted_separation = kSeparationPerStep * character.step_length;
  sample.finest_default = out->wanted_separation;
  sample.max_samples = std::min(load.max_samples, kMaxWalkSamples);
  // The separation the sample budget allows over the box (ResampleTerrainMesh's estimate, 1.6
  // samples per separation squared), said before the long resampling when it is too coarse for
  // the character to walk on, and checked again after it (its memory may allow fewer).
  const double wanted = std::min(out->wanted_separation, out->report.file_separation);
  const double area = SurfaceArea(mesh);
  const double fits =
      1.001 * std::sqrt(1.6 * area / std::max<double>(1, static_cast<double>(sample.max_samples)));
  if (std::max(wanted, fits) > kMaxWalkCoarsening * out->wanted_separation)
    return TooCoarse(path, character, *out, std::max(wanted, fits), area, error);
  status = ResampleTerrainMesh(path, mesh, sample, &out->samples, error, &out->report);
  if (status == Status::kOk && out->report.separation > kMaxWalkCoarsening * out->wanted_separation)
    return TooCoarse(path, character, *out, out->report.separation, area, error);
  return status;
}

}  // namespace footfall
