#include "footfall/cli/load_flags.h"

#include "footfall/cli/number_checks.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/file_extension.h"

namespace footfall::cli {

void AddLoadFlags(CLI::App* command, TerrainLoadOptions* load) {
  command
      ->add_option("--separation", load->separation,
                   "Meshes and height maps: resample so that no surface point is farther "
                   "than this from a sample (world units; 0: mean edge length / cell size)")
      ->check(FiniteAtLeast(0));
  // --smooth-normals sets true (the default), --flat-normals false.
  command->add_flag("--smooth-normals,!--flat-normals", load->smooth_normals,
                    "Meshes and height maps: --flat-normals samples normals from faces instead "
                    "of interpolated corner normals (--smooth-normals, the default)");
  command
      ->add_option("--crease-angle", load->crease_angle_deg,
                   "Meshes and height maps: edges whose faces meet at more than this many "
                   "degrees stay sharp (smooth normals stop at them; 180: smooth everywhere)")
      ->default_val(kDefaultCreaseAngleDeg)
      ->check(FiniteRange(0, 180));
  command
      ->add_option("--seed", load->seed,
                   "Seed of the mesh sampler, a whole number from 0 to 2^64 - 1 (default 1)")
      ->check(Seed());
  command->add_option("--up-axis", load->up_axis, "Height maps: up axis x, y or z")
      ->check(CLI::IsMember({'x', 'y', 'z'}));
  command
      ->add_option("--cell-size", load->cell_size,
                   "Height maps: cell size (default: the .asc CELLSIZE, 1 for .pgm)")
      ->check(FiniteAbove(0));
  command
      ->add_option("--height-scale", load->height_scale,
                   "Height maps: world height of one file unit (metre or grey level)")
      ->check(Finite());
}

bool SeparationApplies(const std::string& path, const TerrainLoadOptions& load,
                       std::string* error) {
  if (!(load.separation > 0) || !IsPointFileExtension(FileExtension(path))) return true;
  *error = path +
           ": --separation resamples meshes and height maps only; a point file is used as it is "
           "(leave --separation out)";
  return false;
}

}  // namespace footfall::cli
