// Height maps: regular grids of heights read from ESRI ASCII grids (.asc) and PGM images (.pgm),
// and their triangle mesh for resampling (mesh_sampler.h).
//
// Grid layout: row 0 is the north (top) row, column 0 the west (left) column, as both formats
// store them. In the mesh, cell (row, col) becomes the vertex at east = col * cell, south =
// row * cell, so the origin is the centre of the north-west cell; the files' georeference
// (xllcorner, yllcorner) is not applied.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "footfall/import/triangle_mesh.h"
#include "footfall/terrain/status.h"

namespace footfall {

// The most cells a height map may have (a 10000 x 10000 grid): larger headers are refused before
// anything is allocated, as are headers declaring more cells than the file holds values.
constexpr size_t kMaxHeightMapCells = 100000000;

struct HeightMap {
  int cols = 0, rows = 0;
  double cell_size = 1;         // [Units: file units] ASC: CELLSIZE; PGM: 1
  std::vector<double> heights;  // rows * cols, row-major from the north-west cell; file units
  std::vector<uint8_t> valid;   // 0 where the file says NODATA
  size_t ValidCount() const;
};

// Reads an ESRI ASCII grid: a header (ncols, nrows, xllcorner|xllcenter, yllcorner|yllcenter,
// cellsize, optional NODATA_value; any case) then nrows * ncols numbers. Cells equal to
// NODATA_value are marked invalid. A leading UTF-8 byte order mark is skipped. Errors: kIoError
// (cannot open), kInvalidArgument (a directory, FIFO or device: CheckInputFile), kParseError with
// "FILE:LINE: what was expected" (bad header, more cells than kMaxHeightMapCells or than the file
// has data for, a value that is not a finite decimal number, truncated data). With
// `cell_size_given` (the caller has a cell size of its own), the header's cellsize, DX and DY are
// neither required nor checked, and out->cell_size is 0.
Status ReadAscGrid(const std::string& path, HeightMap* out, std::string* error,
                   bool cell_size_given = false);

// Reads a PGM image, binary (P5, 8 or 16 bit big-endian by maxval) or ASCII (P2). Heights are
// the grey levels, each at most maxval; every cell is valid. Errors as ReadAscGrid.
Status ReadPgm(const std::string& path, HeightMap* out, std::string* error);

struct HeightMapFrame {
  double cell_size = 1;     // distance between neighbouring cells [Units: wu] [Limit: > 0]
  double height_scale = 1;  // world height of one height unit of the file [Units: wu]
  char up_axis = 'y';       // world axis the heights go along: 'x', 'y' or 'z'
};

// Builds the height map's surface: one vertex per valid cell, two triangles per square of four
// valid cells (split along the north-east to south-west diagonal), one where exactly three are
// valid; every triangle faces up. World axes by up_axis (right-handed in each case):
//   'y': (east, height, south)   'z': (east, north, height)   'x': (height, east, north)
// kInvalidArgument for a bad frame, or a vertex beyond +-terrain::kMaxCoordinate (the message
// names the cell).
Status HeightMapToMesh(const HeightMap& map, const HeightMapFrame& frame, TriangleMesh* out,
                       std::string* error);

}  // namespace footfall
