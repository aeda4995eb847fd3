// Loads terrain samples from any supported file, chosen by extension (any case):
//   .pts .xyz .txt            the point file (footfall/terrain/point_file.h), taken as it is
//   .obj .ply .off .stl       polygon meshes (mesh_reader.h), resampled (mesh_sampler.h)
//   .asc                      ESRI ASCII grids (height_map.h), resampled
//   .pgm                      8/16-bit PGM height maps (height_map.h), resampled
#pragma once

#include <cstdint>
#include <string>

#include "footfall/import/mesh_sampler.h"
#include "footfall/import/triangle_mesh.h"
#include "footfall/terrain/samples.h"

namespace footfall {

// True for the extensions of the point file: pts, xyz, txt (lower case, without the dot).
bool IsPointFileExtension(const std::string& lower_extension);

struct TerrainLoadOptions {
  // Meshes and height maps: the point separation s, the farthest any point of the surface may be
  // from a sample. [Units: wu] [Limit: >= 0] 0 picks a default: the mean edge length of a mesh,
  // the cell size of a height map.
  double separation = 0;
  // Meshes and height maps, when `separation` is 0 and this is > 0: the separation is the finer
  // of the file's default and this (a caller that needs samples this close: a character's
  // steps), coarsened as needed to stay within max_samples. [Units: wu] [Limit: >= 0]
  double finest_default = 0;
  // Meshes and height maps: normals interpolated from the corners' (true; smooth across
  // edges gentler than crease_angle_deg, see CornerNormals) or taken from the face (false).
  bool smooth_normals = true;
  double crease_angle_deg = kDefaultCreaseAngleDeg;  // [Units: degrees]
  // Seed of the deterministic sampler: equal seeds give equal samples.
  uint64_t seed = 1;
  // Height maps: the world axis heights go along ('x', 'y' or 'z'); meshes: the up an open
  // mesh's faces are turned to (TurnOutward). [Default: 'y', as in Maya]
  char up_axis = 'y';
  // Height maps: distance between neighbouring cells. [Units: wu] [Limit: >= 0] 0: the file's
  // CELLSIZE for .asc, 1 for .pgm.
  double cell_size = 0;
  // Height maps: world height of one unit of the file (a metre of .asc, a grey level of .pgm).
  // [Units: wu]
  double height_scale = 1;
  // Meshes and height maps: refuse (kLimitExceeded) a separation predicting more samples.
  size_t max_samples = 20000000;
  // Meshes and height maps: threads cutting triangles (MeshSampleOptions::threads); the samples
  // are the same whatever their number. 0: one per core.
  int threads = 0;
};

// What a load found, for `footfall terrain info` and server logs.
struct TerrainLoadReport {
  std::string format;        // "points", "mesh" or "heightmap"
  size_t vertices = 0;       // meshes: as stored; height maps: valid cells
  size_t faces = 0;          // meshes: polygons read; height maps: triangles built
  size_t skipped_faces = 0;  // meshes: degenerate faces left out
  // Meshes: faces turned over before sampling: each to match the winding of its neighbours
  // (MeshReadReport::turned_faces), then closed shells inside out and open parts facing down
  // along up_axis (TurnOutward).
  size_t rewound_faces = 0;
  MeshTurnover turnover;
  size_t nodata_cells = 0;  // height maps: cells left out
  // Height maps: the surface's area over the area it covers (1 when flat; the secant of the
  // mean slope, area-weighted). Far above 1, the cells are most likely not in the heights'
  // unit (DescribeSteepHeightMap).
  double surface_ratio = 0;
  double area = 0;              // [Units: wu^2] meshes and height maps
  double separation = 0;        // [Units: wu] the separation used (meshes and height maps)
  double file_separation = 0;   // [Units: wu] the file's own default: mean edge / cell size
  size_t samples = 0;           // samples produced
  Vec3 bounds_min, bounds_max;  // world-space bounds of the samples
};

// Bytes of address space the mesh sampler may need per sample: its resident peak is about 340,
// and growing arrays hold old and new copies at once (what a ulimit -v counts; at 400 bytes a
// load within the cap under ulimit -v 4 GB still ran out of memory). Loads sample at most what
// the process's memory holds at this rate.
constexpr uint64_t kSamplingBytesPerSample = 1000;

// What a mesh load turned over, in a phrase ("1 of 2 closed shells inside out: 3030 triangles
// turned over"; faces wound against their neighbours are counted in the file's faces, the rest
// in the triangles they were cut into), or "" when nothing was.
std::string DescribeTurnover(const TerrainLoadReport& report);
// What a load left out of the surface, in a phrase ("2 of 3 faces left out (a vertex used
// twice, a face listed again, or no area)"; for height maps the grid's triangles too thin for
// their length), or "" when nothing was.
std::string DescribeSkippedFaces(const TerrainLoadReport& report);

// A height map steeper than ground (TerrainLoadReport::surface_ratio above
// kSteepHeightMapRatio, slopes of 70 degrees on average) in a phrase naming --cell-size and
// --height-scale, or "" for any other terrain.
std::string DescribeSteepHeightMap(const TerrainLoadReport& report);
constexpr double kSteepHeightMapRatio = 3;

// kInvalidArgument, with "PATH: a cell size or height scale ... applies to height maps (.asc
// .pgm) only, not to a point file" (or a mesh), when `options` give a height map's frame for a
// file of extension `ext` (FileExtension) that is not one: LoadTerrain's own check, for
// callers that refuse flags before loading.
Status CheckHeightMapOnly(const std::string& path, const std::string& ext,
                          const TerrainLoadOptions& options, std::string* error);

// Loads `path` into *out. Errors: kIoError (cannot open), kParseError (malformed content,
// message "FILE:LINE: what was expected" or "FILE: what is wrong"), kInvalidArgument (unknown
// extension or bad option), kLimitExceeded (the separation would give too many samples).
Status LoadTerrain(const std::string& path, const TerrainLoadOptions& options, RawSamples* out,
                   std::string* error, TerrainLoadReport* report = nullptr);

// LoadTerrain's two halves for meshes and height maps, for callers that look at the surface
// before sampling it (footfall generate crops it to where a walk can reach).
// ReadTerrainMesh reads a mesh or height map file into *mesh (height maps under the options'
// frame) and fills the report's format, counts and file_separation; point files are
// kInvalidArgument. ResampleTerrainMesh samples a mesh as LoadTerrain would, with
// report->file_separation as the file's default, and fills the rest of the report.
Status ReadTerrainMesh(const std::string& path, const TerrainLoadOptions& options,
                       TriangleMesh* mesh, std::string* error, TerrainLoadReport* report);
Status ResampleTerrainMesh(const std::string& path, const TriangleMesh& mesh,
                           const TerrainLoadOptions& options, RawSamples* out, std::string* error,
                           TerrainLoadReport* report);

}  // namespace footfall
