#include "terrain_flags.h"

namespace footfall::cli {

void AddTerrainFlags(CLI::App* command, TerrainFlags* flags) {
  command->add_option("--terrain", flags->terrain,
                      "Terrain file on this machine: points (.pts .xyz .txt)");
  command->add_option("--server-terrain", flags->server_terrain,
                      "Terrain file under footfalld's --data-root, read by the server");
  command->add_option("--server", flags->server,
                      "footfalld HOST:PORT; without it the embedded engine answers");
  command->add_option("--separation", flags->load.separation,
                      "Mesh resampling distance between samples (world units)")
      ->check(CLI::NonNegativeNumber);
  command->add_flag("!--smooth-normals,--flat-normals", flags->load.smooth_normals,
                    "Mesh sample normals from faces instead of interpolated vertex normals");
  command->add_option("--seed", flags->load.seed, "Seed of the mesh sampler");
  command->add_option("--up-axis", flags->load.up_axis, "Height maps: up axis x, y or z")
      ->check(CLI::IsMember({'x', 'y', 'z'}));
  command->add_option("--cell-size", flags->load.cell_size, "PGM height maps: cell size")
      ->check(CLI::PositiveNumber);
  command->add_option("--height-scale", flags->load.height_scale,
                      "PGM height maps: height of one grey level");
  command->add_option("--timeout", flags->timeout_s, "RPC call timeout in seconds")
      ->check(CLI::PositiveNumber);
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
  if (flags.server.empty()) {
    *session = MakeEmbeddedSession();
  } else {
    RpcOptions options;
    options.call_timeout_s = flags.timeout_s;
    const Status status = ParseHostPort(flags.server, &options, error);
    if (status != Status::kOk) return status;
    *session = MakeRpcSession(options);
  }
  const Status status = flags.terrain.empty()
                            ? (*session)->LoadServerFile(flags.server_terrain,
                                                         flags.load.separation, terrain)
                            : (*session)->LoadFile(flags.terrain, flags.load, terrain);
  if (status != Status::kOk) *error = (*session)->last_error();
  return status;
}

}  // namespace footfall::cli
