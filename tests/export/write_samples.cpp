// Writes the exporter test walks as glTF and MEL files into a folder, for the Khronos
// validator tests and for a look in Maya.
// Usage: export_samples DIR
// Creates DIR if needed and writes walk.gltf, walk.glb, crowd.gltf, crowd.glb, empty.gltf,
// far.gltf and far.glb (the biped at UTM-like coordinates: tracks under a root origin node),
// walk_feet.gltf and crowd_feet.glb (with the feet's rotations), far_cm.glb (the far walk taken
// as centimetres, written in metres), walk.mel, crowd.mel and
// broken.gltf: walk.gltf with its samplers switched to CUBICSPLINE
// without the tangents that needs, which a working validator must reject.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "footfall/export/walk_writer.h"
#include "walk_fixtures.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: export_samples DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "export_samples: cannot create '%s': %s\n", dir.c_str(),
                 ec.message().c_str());
    return 1;
  }
  const footfall::Walk biped = footfall::test::BipedWalk();
  const footfall::Walk crowd = footfall::test::CrowdWalk();
  const footfall::Walk far = footfall::test::FarWalk();
  footfall::Walk far_cm = far;
  far_cm.unit = "cm";
  const footfall::Walk empty;
  const struct {
    const footfall::Walk* walk;
    const char* file;
    bool foot_rotations;
  } samples[] = {{&biped, "walk.gltf", false},     {&biped, "walk.glb", false},
                 {&crowd, "crowd.gltf", false},    {&crowd, "crowd.glb", false},
                 {&empty, "empty.gltf", false},    {&far, "far.gltf", false},
                 {&far, "far.glb", false},         {&biped, "walk_feet.gltf", true},
                 {&crowd, "crowd_feet.glb", true}, {&far_cm, "far_cm.glb", true},
                 {&biped, "walk.mel", false},      {&crowd, "crowd.mel", false}};
  for (const auto& sample : samples) {
    const std::string path = dir + "/" + sample.file;
    std::string error;
    footfall::WalkExportOptions options;
    options.foot_rotations = sample.foot_rotations;
    if (footfall::WriteWalk(*sample.walk, path, options, &error) != footfall::Status::kOk) {
      std::fprintf(stderr, "export_samples: %s\n", error.c_str());
      return 1;
    }
    std::printf("wrote %s\n", path.c_str());
  }
  std::ifstream in(dir + "/walk.gltf", std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string linear = "\"LINEAR\"";
  size_t replaced = 0;
  for (size_t at = text.find(linear); at != std::string::npos; at = text.find(linear, at)) {
    text.replace(at, linear.size(), "\"CUBICSPLINE\"");
    ++replaced;
  }
  std::ofstream out(dir + "/broken.gltf", std::ios::binary);
  out << text;
  if (replaced == 0 || !out.flush()) {
    std::fprintf(stderr, "export_samples: cannot write %s/broken.gltf\n", dir.c_str());
    return 1;
  }
  std::printf("wrote %s/broken.gltf\n", dir.c_str());
  return 0;
}
