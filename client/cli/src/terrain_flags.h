// The flags every terrain-using command shares (--terrain, --server, --separation ...) and the
// session they open: embedded by default, footfalld over RPC with --server.
#pragma once

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "footfall/cli/load_flags.h"
#include "footfall/client/terrain_session.h"

namespace footfall::cli {

struct TerrainFlags {
  std::string terrain;         // a terrain file on this machine
  std::string server_terrain;  // a path under footfalld's data root (RPC only)
  std::string server;          // HOST:PORT; empty: embedded engine
  TerrainLoadOptions load;
  double timeout_s = 10;
  int threads = 1;  // threads of the embedded engine's batch queries (unused with --server)
};

// Adds --terrain (required unless `terrain_optional`), --server-terrain, --server, --separation,
// --flat-normals, --seed, --up-axis, --cell-size, --height-scale, --timeout.
void AddTerrainFlags(CLI::App* command, TerrainFlags* flags);

// Opens the session the flags ask for (embedded, or footfalld with --server) without loading
// anything. On failure returns the status and a one-line message.
Status OpenSession(const TerrainFlags& flags, std::unique_ptr<TerrainSession>* session,
                   std::string* error);

// Checks the flags before anything is read or loaded: exactly one of --terrain and
// --server-terrain, the resampling flags only for what they apply to, --server-terrain with
// --server, and --server a HOST:PORT. On failure returns the status and a one-line message.
Status CheckTerrainFlags(const TerrainFlags& flags, std::string* error);

// Opens the session the flags ask for and loads the terrain (checked by CheckTerrainFlags
// first). On failure returns the status and a one-line message naming what failed.
Status OpenTerrain(const TerrainFlags& flags, std::unique_ptr<TerrainSession>* session,
                   TerrainHandle* terrain, std::string* error);

}  // namespace footfall::cli
