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
  return WriteWalk(walk, path, WalkExportOptions{}, error);
}

Status WriteWalk(const Walk& walk, const std::string& path, const WalkExportOptions& options,
                 std::string* error) {
  const std::string ext = FileExtension(path);
  if (ext == "gltf" || ext == "glb") {
    GltfOptions gltf;
    gltf.binary = ext == "glb";
    gltf.foot_rotations = options.foot_rotations;
    return WriteGltf(walk, path, gltf, error);
  }
  if (ext == "mel") {
    MelOptions mel;
    mel.foot_rotations = options.foot_rotations;
    return WriteMel(walk, path, mel, error);
  }
  const std::string what = ext.empty() ? "no extension" : "unknown extension '." + ext + "'";
  walk_export::SetError(error, "cannot write walk '" + path + "': " + what +
                                   " (footfall::WriteWalk writes .gltf, .glb and .mel)");
  return Status::kInvalidArgument;
}

}  // namespace footfall
