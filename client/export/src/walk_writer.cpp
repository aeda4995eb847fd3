#include "footfall/export/walk_writer.h"

#include <cctype>

#include "footfall/export/gltf_writer.h"
#include "footfall/export/mel_writer.h"
#include "walk_prep.h"

namespace footfall {
namespace {

// The extension of the file name in `path`, lower case, with its dot; "" when it has none.
std::string Extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

bool IsWalkExportPath(const std::string& path) {
  const std::string ext = Extension(path);
  return ext == ".gltf" || ext == ".glb" || ext == ".mel";
}

Status WriteWalk(const Walk& walk, const std::string& path, std::string* error) {
  const std::string ext = Extension(path);
  if (ext == ".gltf" || ext == ".glb") {
    GltfOptions options;
    options.binary = ext == ".glb";
    return WriteGltf(walk, path, options, error);
  }
  if (ext == ".mel") return WriteMel(walk, path, error);
  const std::string what = ext.empty() ? "no extension" : "unknown extension '" + ext + "'";
  walk_export::SetError(error, "cannot write walk '" + path + "': " + what +
                                   " (footfall::WriteWalk writes .gltf, .glb and .mel)");
  return Status::kInvalidArgument;
}

}  // namespace footfall
