// Structural checks of mesh files before OpenMesh reads them, so that truncated or malformed files
// fail with a message naming the file and line instead of loading partially. Private to
// footfall::import (mesh_reader.cpp).
#pragma once

#include <string>
#include <vector>

#include "footfall/terrain/status.h"
#include "footfall/terrain/vec3.h"

namespace footfall::detail {

// Each returns kOk or kParseError with "FILE:LINE: what was expected" (or "FILE: ..." for binary
// data) in *error. They check counts, vertex indices and that coordinates are finite numbers;
// they do not build the mesh. On kOk, *faces is the number of faces the file declares (-1 when
// unknown), so that faces OpenMesh drops (repeated vertices) can be counted. Coordinates must be
// within +-terrain::kMaxCoordinate. OBJ and OFF also give the vertices' coordinates in double, in
// file order (OpenMesh's readers parse them as float, 7 digits).
Status CheckObjFile(const std::string& path, long long* faces, std::vector<Vec3>* coordinates,
                    std::string* error);
Status CheckOffFile(const std::string& path, long long* faces, std::vector<Vec3>* coordinates,
                    std::string* error);
Status CheckPlyFile(const std::string& path, long long* faces, std::string* error);
Status CheckStlFile(const std::string& path, std::string* error);

}  // namespace footfall::detail
