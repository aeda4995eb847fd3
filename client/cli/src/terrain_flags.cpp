#include "terrain_flags.h"

#include "footfall/cli/number_checks.h"

namespace footfall::cli {

void AddTerrainFlags(CLI::App* command, TerrainFlags* flags) {
  // Given empty (a script's unset variable: --server "$HOST"), each is refused, not taken as
  // absent: --server "" ran the embedded engine and --server-terrain "" was ignored, silently.
  command
      ->add_option("--terrain", flags->terrain,
                   "Terrain file on this machine: points (.pts .xyz .txt), mesh (.obj .ply .off "
                   ".stl) or height map (.asc .pgm)")
      ->check(NotBlank("a terrain file"));
  command
      ->add_option("--server-terrain", flags->server_terrain,
                   "Terrain file under footfalld's --data-root, read by the server")
      ->check(NotBlank("a terrain file under footfalld's data root"));
  command
      ->add_option("--server", flags->server,
                   "footfalld HOST:PORT; without it the embedded engine answers")
      ->check(NotBlank("a footfalld HOST:PORT"));
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

Status CheckTerrainFlags(const TerrainFlags& flags, std::string* error) {
  if (flags.terrain.empty() == flags.server_terrain.empty()) {
    *error = "give exactly one of --terrain FILE or --server-terrain PATH";
    return Status::kInvalidArgument;
  }
  if (!ResamplingFlagsApply(flags.terrain.empty() ? flags.server_terrain : flags.terrain,
                            flags.load, error)) {
    return Status::kInvalidArgument;
  }
  if (!flags.server_terrain.empty() && flags.server.empty()) {
    *error = "--server-terrain needs --server HOST:PORT";
    return Status::kInvalidArgument;
  }
  RpcOptions options;
  return flags.server.empty() ? Status::kOk : ParseHostPort(flags.server, &options, error);
}

Status OpenTerrain(const TerrainFlags& flags, std::unique_ptr<TerrainSession>* session,
                   TerrainHandle* terrain, std::string* error) {
  Status status = CheckTerrainFlags(flags, error);
  if (status != Status::kOk) return status;
  status = OpenSession(flags, session, error);
  if (status != Status::kOk) return status;
  status = flags.terrain.empty()
               ? (*session)->LoadServerFile(flags.server_terrain, flags.load, terrain)
               : (*session)->LoadFile(flags.terrain, flags.load, terrain);
  if (status != Status::kOk) *error = (*session)->last_error();
  return status;
}

}  // namespace footfall::cli
