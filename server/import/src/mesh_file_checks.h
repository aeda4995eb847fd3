// Parsers of mesh files (OBJ, OFF, PLY, STL) into vertices and polygons, each checking the file as
// it reads, so that truncated or malformed files fail with a message naming the file and line
// instead of loading partially. Private to footfall::import (mesh_reader.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "footfall/terrain/status.h"
#include "footfall/terrain/vec3.h"

namespace footfall::detail {

// A polygon mesh as a file stores it: nothing skipped, merged (but STL's repeated corners) or
// triangulated yet.
struct ParsedMesh {
  std::vector<Vec3> vertices;         // in file order, world space [(x, y, z)]
  std::vector<uint32_t> corners;      // every face's 0-based vertex indices, face after face
  std::vector<size_t> face_start{0};  // per face + 1: offsets into corners
  std::vector<size_t> face_line;      // per face: its 1-based line (text files; else empty)
  size_t Faces() const { return face_start.size() - 1; }
  // Appends a face of the corners added to `corners` since the last one.
  void EndFace(size_t line) {
    face_start.push_back(corners.size());
    if (line) face_line.push_back(line);
  }
};

// Each returns kOk, or kParseError with "FILE:LINE: what was expected" (or "FILE: ..." for binary
// data) in *error. Faces have 3 or more indices of existing vertices; coordinates are finite
// decimal numbers within +-terrain::kMaxCoordinate, read in double (binary PLY and STL store
// floats). Normals, texture coordinates and colours are checked as far as the format needs to find
// the next value, and dropped.
Status ParseObjFile(const std::string& path, ParsedMesh* out, std::string* error);
Status ParseOffFile(const std::string& path, ParsedMesh* out, std::string* error);
Status ParsePlyFile(const std::string& path, ParsedMesh* out, std::string* error);
// STL stores every facet's corners: corners at the same point become one vertex.
Status ParseStlFile(const std::string& path, ParsedMesh* out, std::string* error);

}  // namespace footfall::detail
