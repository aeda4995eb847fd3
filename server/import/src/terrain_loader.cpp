#include "footfall/import/terrain_loader.h"

#include <algorithm>
#include <cctype>

#include "footfall/terrain/point_file.h"

namespace footfall {
namespace {

std::string LowerExtension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

Status LoadTerrain(const std::string& path, const TerrainLoadOptions& options, RawSamples* out,
                   std::string* error, TerrainLoadReport* report) {
  (void)options;
  const std::string ext = LowerExtension(path);
  if (ext == "pts" || ext == "xyz" || ext == "txt") {
    if (report) *report = TerrainLoadReport{}, report->format = "points";
    return ReadPointFile(path, out, error);
  }
  out->clear();
  if (error) {
    *error = path + ": unknown terrain file extension '" + ext +
             "' (expected .pts, .xyz or .txt point files)";
  }
  return Status::kInvalidArgument;
}

}  // namespace footfall
