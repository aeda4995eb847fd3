// Reads polygon meshes (OBJ, PLY, OFF, STL; chosen by extension) into a TriangleMesh. Polygons
// are triangulated by ear clipping in their plane (TriangulatePolygon: the fan of the first
// corner for a convex polygon, concave ones cut along their inside only). Faces with
// repeated vertices, and faces whose triangles all have zero area, are skipped and counted.
// A face wound against its neighbours (fewer of them in its sheet) is turned to match them.
// Normals, texture coordinates and colours in the file are ignored.
#pragma once

#include <cstddef>
#include <string>

#include "footfall/import/triangle_mesh.h"
#include "footfall/terrain/status.h"

namespace footfall {

struct MeshReadReport {
  size_t vertices = 0;       // as stored in the file (STL: distinct corner points)
  size_t faces = 0;          // polygons in the file, skipped ones included
  size_t skipped_faces = 0;  // of those, left out: a repeated vertex, or zero area
  size_t turned_faces = 0;   // of those, turned over to match the winding of their neighbours
};

// True for the extensions ReadMesh takes: obj, ply, off, stl (any case, without the dot).
bool IsMeshExtension(const std::string& lower_extension);

// Reads `path` into *out. Errors, each with a message naming the file (and the line where the
// format is text): kIoError (cannot open), kParseError (empty file, no faces, truncated data,
// a non-finite coordinate, a face using a missing vertex, a non-manifold edge or vertex),
// kInvalidArgument (not a mesh extension; a directory, FIFO or device: CheckInputFile).
Status ReadMesh(const std::string& path, TriangleMesh* out, std::string* error,
                MeshReadReport* report = nullptr);

}  // namespace footfall
