#include "footfall/export/walk_writer.h"

#include "footfall/export/gltf_writer.h"
#include "footfall/export/mel_writer.h"
#include "footfall/terrain/file_extension.h"
#include "walk_prep.h"

namespace footfall {

bool IsWalkExportPath(const std::string& path) {
  const std::string ext = FileExtension(path);
  return ext == "gltf" || ext == "glb" || ext == "mel";
}

Status WriteWalk(const Walk& walk, const std::string& path, std::string* error) {
  const std::string ext = FileExtension(path);
  if (ext == "gltf" || ext == "glb") {
    GltfOptions options;
    options.binary = ext == "glb";
    return WriteGltf(walk, path, options, error);
  }
  if (ext == "mel") return WriteMel(walk, path, error);
  const std::string what = ext.empty() ? "no extension" : "unknown extension '." + ext + "'";
  walk_export::SetError(error, "cannot write walk '" + path + "': " + what +
                                   " (footfall::WriteWalk writes .gltf, .glb and .mel)");
  return Status::kInvalidArgument;
}

}  // namespace footfall
