// Loads terrain samples from any supported file, chosen by extension:
//   .pts .xyz .txt  the point file (footfall/terrain/point_file.h)
// Meshes and height maps are resampled into samples with the options below.
#pragma once

#include <cstdint>
#include <string>

#include "footfall/terrain/samples.h"

namespace footfall {

struct TerrainLoadOptions {
  // Mesh resampling: distance between samples. [Units: wu] [Limit: >= 0] 0 picks a default.
  double separation = 0;
  // Mesh normals: interpolated from vertex normals (true) or taken from the face (false).
  bool smooth_normals = true;
  // Seed of the deterministic mesh sampler.
  uint64_t seed = 1;
  // Height maps: the world axis heights go along ('x', 'y' or 'z'). [Default: 'y', as in Maya]
  char up_axis = 'y';
  // PGM height maps: cell size [Units: wu] and height of one grey level [Units: wu].
  double cell_size = 1;
  double height_scale = 1;
};

// What a load found, for `footfall terrain info` and server logs.
struct TerrainLoadReport {
  std::string format;   // "points", "mesh", "heightmap"
  size_t vertices = 0;  // meshes
  size_t faces = 0;
  size_t skipped_faces = 0;
  double area = 0;      // [Units: wu^2] meshes and height maps
};

// Loads `path` into *out. Errors: kIoError (cannot open), kParseError (malformed content,
// message "FILE:LINE: what was expected"), kInvalidArgument (unknown extension or bad option).
Status LoadTerrain(const std::string& path, const TerrainLoadOptions& options, RawSamples* out,
                   std::string* error, TerrainLoadReport* report = nullptr);

}  // namespace footfall
