// The extension of a file name, lower-cased, which every reader and writer dispatches on, and
// its stem.
#pragma once

#include <string>

#include "footfall/terrain/ascii.h"

namespace footfall {

// "dir/Walk.GLB" -> "glb"; "" when the last path component has no dot.
inline std::string FileExtension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = AsciiLower(c);
  return ext;
}

// "dir/biped.json" -> "biped": the last path component without its extension ("" for "dir/").
inline std::string FileStem(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  if (dot != std::string::npos && dot > 0) name.erase(dot);
  return name;
}

}  // namespace footfall
