// Generates a walk with the installed C++ libraries and prints its JSON: the same bytes
// `footfall generate` writes for the same terrain and request.
// Usage: walk_consumer TERRAIN REQUEST_JSON
#include <footfall/client/terrain_session.h>
#include <footfall/steps/generate_request.h>
#include <footfall/steps/generator.h>
#include <footfall/steps/walk_json.h>
#include <footfall/version.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#if FOOTFALL_VERSION_NUMBER != PACKAGE_VERSION_NUMBER
#error "footfall/version.h and the CMake package disagree on the version"
#endif
static_assert(sizeof(FOOTFALL_VERSION) == sizeof(PACKAGE_VERSION) &&
                  std::char_traits<char>::compare(FOOTFALL_VERSION, PACKAGE_VERSION,
                                                  sizeof(PACKAGE_VERSION)) == 0,
              "FOOTFALL_VERSION is the package's version string");

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: walk_consumer TERRAIN REQUEST_JSON\n");
    return 1;
  }
  std::ifstream request_file(argv[2]);
  std::stringstream request;
  request << request_file.rdbuf();
  footfall::Character character;
  footfall::GenerateOptions options;
  std::string error;
  if (footfall::ParseGenerateRequest(request.str(), &character, &options, &error) !=
      footfall::Status::kOk) {
    std::fprintf(stderr, "request: %s\n", error.c_str());
    return 1;
  }
  std::unique_ptr<footfall::TerrainSession> session = footfall::MakeEmbeddedSession();
  footfall::TerrainHandle terrain = 0;
  if (session->LoadFile(argv[1], footfall::TerrainLoadOptions{}, &terrain) !=
      footfall::Status::kOk) {
    std::fprintf(stderr, "load: %s\n", session->last_error().c_str());
    return 1;
  }
  footfall::Walk walk;
  if (footfall::GenerateWalk(*session, terrain, character, options, &walk, &error) !=
      footfall::Status::kOk) {
    std::fprintf(stderr, "generate: %s\n", error.c_str());
    return 1;
  }
  std::fputs(footfall::WalkToJson(walk).c_str(), stdout);
  return 0;
}
