#include "footfall/cli/load_flags.h"

#include <string>
#include <vector>

#include "footfall/cli/number_checks.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/file_extension.h"

namespace footfall::cli {

std::vector<CLI::Option*> AddLoadFlags(CLI::App* command, TerrainLoadOptions* load) {
  return {
      command
          ->add_option("--separation", load->separation,
                       "Meshes and height maps: resample so that no surface point is farther "
                       "than this from a sample (world units; 0: mean edge length / cell size)")
          ->check(FiniteAtLeast(0)),
      // --smooth-normals sets true (the default), --flat-normals false.
      command->add_flag("--smooth-normals,!--flat-normals", load->smooth_normals,
                        "Meshes and height maps: --flat-normals samples normals from faces "
                        "instead of interpolated corner normals (--smooth-normals, the default)"),
      command
          ->add_option("--crease-angle", load->crease_angle_deg,
                       "Meshes and height maps: edges whose faces meet at more than this many "
                       "degrees stay sharp (smooth normals stop at them; 180: smooth everywhere)")
          ->default_val(kDefaultCreaseAngleDeg)
          ->check(FiniteRange(0, 180)),
      command
          ->add_option("--seed", load->seed,
                       "Seed of the mesh sampler, a whole number from 0 to 2^64 - 1 (default 1)")
          ->transform(Seed()),
      command
          ->add_option("--up-axis", load->up_axis,
                       "Up axis x, y or z: height maps go up along it, and open meshes are turned "
                       "to face up "
                       "along it")
          ->check(CLI::IsMember({'x', 'y', 'z'})),
      command
          ->add_option("--cell-size", load->cell_size,
                       "Height maps: cell size (default: the .asc CELLSIZE, 1 for .pgm)")
          ->check(FiniteAbove(0)),
      command
          ->add_option("--height-scale", load->height_scale,
                       "Height maps: world height of one file unit (metre or grey level)")
          ->check(Finite())};
}

bool ResamplingFlagsApply(const std::string& path, const TerrainLoadOptions& load,
                          std::string* error) {
  if (!IsPointFileExtension(FileExtension(path))) return true;
  // The flags of AddLoadFlags that only resampling reads, given other than their defaults.
  // (--cell-size and --height-scale are refused by the loader itself, for meshes too.)
  const TerrainLoadOptions defaults;
  std::vector<std::string> given;
  if (load.separation > 0) given.push_back("--separation");
  if (load.smooth_normals != defaults.smooth_normals) given.push_back("--flat-normals");
  if (load.crease_angle_deg != defaults.crease_angle_deg) given.push_back("--crease-angle");
  if (load.seed != defaults.seed) given.push_back("--seed");
  if (load.up_axis != defaults.up_axis) given.push_back("--up-axis");
  if (given.empty()) return true;
  std::string names;
  for (size_t i = 0; i < given.size(); ++i)
    names += (i == 0 ? "" : i + 1 == given.size() ? " and " : ", ") + given[i];
  *error = path + ": " + names + (given.size() == 1 ? " applies" : " apply") +
           " to meshes and height maps, which are resampled; a point file is used as it is "
           "(leave " +
           (given.size() == 1 ? given[0] : std::string("them")) + " out)";
  return false;
}

}  // namespace footfall::cli
