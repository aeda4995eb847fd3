#include "terrain_flags.h"

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
  command->add_option("--seed", load->seed, "Seed of the mesh sampler");
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

void AddTerrainFlags(CLI::App* command, TerrainFlags* flags) {
  command->add_option("--terrain", flags->terrain,
                      "Terrain file on this machine: points (.pts .xyz .txt), mesh (.obj .ply .off "
                      ".stl) or height map (.asc .pgm)");
  command->add_option("--server-terrain", flags->server_terrain,
                      "Terrain file under footfalld's --data-root, read by the server");
  command->add_option("--server", flags->server,
                      "footfalld HOST:PORT; without it the embedded engine answers");
  AddLoadFlags(command, &flags->load);
  command
      ->add_option("--timeout", flags->timeout_s,
                   "RPC call timeout in seconds (a --server-terrain load waits at least 300 s)")
      ->check(FiniteRange(0.001, 1e6));
}

Status OpenSession(const TerrainFlags& flags, std::unique_ptr<TerrainSession>* session,
                   std::string* error) {
  if (flags.server.empty()) {
    *session = MakeEmbeddedSession(flags.threads);
    return Status::kOk;
  }
  RpcOptions options;
  options.call_timeout_s = flags.timeout_s;
  const Status status = ParseHostPort(flags.server, &options, error);
  if (status != Status::kOk) return status;
  *session = MakeRpcSession(options);
  return Status::kOk;
}

Status OpenTerrain(const TerrainFlags& flags, std::unique_ptr<TerrainSession>* session,
                   TerrainHandle* terrain, std::string* error) {
  if (flags.terrain.empty() == flags.server_terrain.empty()) {
    *error = "give exactly one of --terrain FILE or --server-terrain PATH";
    return Status::kInvalidArgument;
  }
  if (!flags.server_terrain.empty() && flags.server.empty()) {
    *error = "--server-terrain needs --server HOST:PORT";
    return Status::kInvalidArgument;
  }
  Status status = OpenSession(flags, session, error);
  if (status != Status::kOk) return status;
  status = flags.terrain.empty()
               ? (*session)->LoadServerFile(flags.server_terrain, flags.load, terrain)
               : (*session)->LoadFile(flags.terrain, flags.load, terrain);
  if (status != Status::kOk) *error = (*session)->last_error();
  return status;
}

}  // namespace footfall::cli
