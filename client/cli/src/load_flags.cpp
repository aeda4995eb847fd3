#include "footfall/cli/load_flags.h"

#include "footfall/cli/number_checks.h"

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
  // (CLI11 read "-1" as 2^64 - 1.)
  command
      ->add_option("--seed", load->seed,
                   "Seed of the mesh sampler, a whole number from 0 to 2^64 - 1 (default 1)")
      ->check(CLI::Validator(
          [](std::string& input) -> std::string {
            if (!input.empty() && input.size() <= 20 &&
                input.find_first_not_of("0123456789") == std::string::npos &&
                (input.size() < 20 || input <= "18446744073709551615"))
              return std::string();
            return "'" + input + "' is not a whole number from 0 to 18446744073709551615";
          },
          "SEED"));
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

}  // namespace footfall::cli
