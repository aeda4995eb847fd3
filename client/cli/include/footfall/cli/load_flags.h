// The flags of loading meshes and height maps (--separation, --flat-normals, --crease-angle,
// --seed, --up-axis, --cell-size, --height-scale), shared by every command that reads a terrain
// file: footfall's and footfall-view's.
#pragma once

#include <vector>

#include <CLI/CLI.hpp>

#include "footfall/client/terrain_session.h"

namespace footfall::cli {

// Adds the options of loading meshes and height maps to `command`, writing into *load. Bad
// values are CLI11 validation errors (the command's parse fails with a message naming the flag).
// Returns the options added (to tell whether any was given).
std::vector<CLI::Option*> AddLoadFlags(CLI::App* command, TerrainLoadOptions* load);

// Resampling flags (--separation, --flat-normals, --crease-angle, --seed, --up-axis) given for a
// point file, which is used as it is (never resampled): false and a message naming the file and
// the flags; true otherwise.
bool ResamplingFlagsApply(const std::string& path, const TerrainLoadOptions& load,
                          std::string* error);

}  // namespace footfall::cli
