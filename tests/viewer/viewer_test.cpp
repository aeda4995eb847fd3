// footfall-view, run headless on a private Xvfb: screenshots of queries and walks checked
// pixel by pixel, a live server followed, and bad inputs.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include "footfall/import/terrain_loader.h"
#include "footfall/steps/walk_json.h"
#include "footfall/terrain/brute_force.h"
#include "footfall/terrain/grid.h"
#include "footfall/viewer/camera.h"
#include "footfall/viewer/draw_list.h"
#include "footfall/viewer/query_view.h"
#include "footfall/viewer/walk_pose.h"
#include "process.h"

namespace footfall {
namespace {

using nlohmann::json;
using test::Run;
using test::RunResult;

const std::string kView = FOOTFALL_VIEW;
const std::string kTerrain = std::string(FOOTFALL_DATA_DIR) + "/terrain/hills.pts";
constexpr double kTimeout = 60;  // [Units: s] generous: llvmpipe on a loaded 2-core machine

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  glm::ivec3 At(int x, int y) const {
    const size_t i =
        (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

Image ReadPng(const std::string& path) {
  Image image;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
  INFO("reading " << path);
  REQUIRE(data != nullptr);
  image.rgb.assign(data, data + static_cast<size_t>(image.width) * image.height * 3);
  stbi_image_free(data);
  return image;
}

bool Near(const glm::ivec3& a, const glm::ivec3& b, int tolerance = 8) {
  return std::abs(a.x - b.x) <= tolerance && std::abs(a.y - b.y) <= tolerance &&
         std::abs(a.z - b.z) <= tolerance;
}

// How many pixels within `radius` of `pixel` have colour `color`.
int CountColorNear(const Image& image, glm::vec2 pixel, int radius, glm::ivec3 color) {
  int count = 0;
  for (int y = static_cast<int>(pixel.y) - radius; y <= static_cast<int>(pixel.y) + radius; ++y) {
    for (int x = static_cast<int>(pixel.x) - radius; x <= static_cast<int>(pixel.x) + radius; ++x) {
      if (x >= 0 && y >= 0 && x < image.width && y < image.height && Near(image.At(x, y), color))
        ++count;
    }
  }
  return count;
}

int CountColor(const Image& image, glm::ivec3 color) {
  return CountColorNear(image, {image.width / 2.0f, image.height / 2.0f},
                        std::max(image.width, image.height), color);
}

// The test's own projection (not the viewer's camera code): y up, 45 degree vertical FOV,
// pixels from the top-left corner.
glm::vec2 Project(const glm::dvec3& eye, const glm::dvec3& target, int width, int height,
                  const glm::dvec3& p) {
  const glm::dmat4 view = glm::lookAt(eye, target, glm::dvec3(0, 1, 0));
  const glm::dmat4 proj =
      glm::perspective(glm::radians(45.0), static_cast<double>(width) / height, 0.1, 1000.0);
  const glm::dvec4 clip = proj * view * glm::dvec4(p, 1);
  return {static_cast<float>((clip.x / clip.w * 0.5 + 0.5) * width),
          static_cast<float>((0.5 - clip.y / clip.w * 0.5) * height)};
}

RunResult View(std::vector<std::string> args) {
  args.insert(args.begin(), kView);
  RunResult r = Run(args, {test::XDisplay()}, kTimeout);
  INFO("footfall-view stderr: " << r.err);
  REQUIRE_FALSE(r.timed_out);
  return r;
}

const glm::ivec3 kChosen(255, 0, 255);

// The port footfalld writes to its --port-file once listening ("" after 10 s).
std::string WaitForPort(const std::string& path) {
  std::string port;
  for (int i = 0; i < 500 && port.empty(); ++i) {
    port = test::ReadFile(path);
    while (!port.empty() && (port.back() == '\n' || port.back() == ' ')) port.pop_back();
    if (port.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return port;
}

// A real footfalld on a free loopback port, its port file in `dir` (stopped when destroyed).
struct LocalServer {
  explicit LocalServer(const std::string& dir)
      : child({FOOTFALLD, "--listen", "127.0.0.1:0", "--port-file", dir + "/port", "--no-rpcbind"},
              {}),
        port(WaitForPort(dir + "/port")),
        address("127.0.0.1:" + port) {}
  test::Child child;
  const std::string port;     // "" when it did not start listening
  const std::string address;  // 127.0.0.1:port
};

TEST_CASE("screenshot of a next query shows the chosen sample where it projects",
          "[viewer][screenshot]") {
  const std::string dir = test::TempDir();
  const glm::dvec3 eye(10, 14, -6), target(14, 0, 14);
  const int width = 800, height = 500;
  const StepQuery query{{10, 1, 10}, {1.2, 0, 0.3}};
  const RunResult r = View({"--terrain", kTerrain, "--query", "next 10 1 10 1.2 0 0.3", "--camera",
                            "10 14 -6 14 0 14", "--size", "800x500", "--screenshot",
                            dir + "/shot.png", "--dump-state", dir + "/state.json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);

  // The oracle: brute force over the same terrain.
  RawSamples samples;
  std::string error;
  REQUIRE(LoadTerrain(kTerrain, {}, &samples, &error) == Status::kOk);
  REQUIRE(ValidateAndNormalize(&samples, &error) == Status::kOk);
  TerrainGrid grid;
  REQUIRE(TerrainGrid::Build(samples, {}, &grid, &error) == Status::kOk);
  const Foothold expected = BruteForce(grid).Next(query, 0);
  REQUIRE(expected.status == Status::kOk);

  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  REQUIRE(state["queries"].size() == 1);
  CHECK(state["queries"][0]["index"] == expected.index);
  CHECK(state["queries"][0]["candidates"].get<int>() > 0);

  const Image image = ReadPng(dir + "/shot.png");
  REQUIRE(image.width == width);
  REQUIRE(image.height == height);
  const glm::vec2 pixel =
      Project(eye, target, width, height, {expected.point.x, expected.point.y, expected.point.z});
  INFO("chosen sample projects to " << pixel.x << ", " << pixel.y);
  const glm::vec2 dumped(state["queries"][0]["pixel"][0].get<float>(),
                         state["queries"][0]["pixel"][1].get<float>());
  CHECK(glm::length(dumped - pixel) < 2.0f);
  // The chosen sample is a 15 px magenta square centred on its projection.
  CHECK(CountColorNear(image, pixel, 4, kChosen) >= 40);
  CHECK(CountColor(image, kChosen) < 600);  // and nowhere else to speak of

  // Terrain coloured by normal: mostly-up normals are green-dominant.
  int terrain = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const glm::ivec3 c = image.At(x, y);
      if (c.y > c.x + 40 && c.y > c.z + 40) ++terrain;
    }
  }
  const double share = static_cast<double>(terrain) / (width * height);
  INFO("terrain share " << share);
  CHECK(share > 0.25);
  CHECK(share < 0.98);
}

TEST_CASE("a camera over the terrain keeps in view what lies beyond the terrain's far side",
          "[viewer][camera]") {
  // (A box around the eye set the near plane from its own far side, which capped the far plane
  // there: a walk 20 m past a 40 m terrain was clipped, though --dump-state said it was
  // visible.)
  viewer::OrbitCamera camera;
  camera.LookAt({0, 8, 0}, {50, 1, 0});
  const std::vector<viewer::RenderBox> boxes = {{{-20, 0, -20}, {20, 1, 20}},  // under the eye
                                                {{48, 0, -2}, {70, 2, 2}}};    // beyond it
  const glm::dmat4 clip_from_render = camera.Projection(1.5, boxes) * camera.View();
  for (const glm::dvec3& p : {glm::dvec3(69, 1, 0), glm::dvec3(50, 1, 0), glm::dvec3(10, 0.5, 0)}) {
    const glm::dvec4 clip = clip_from_render * glm::dvec4(p, 1);
    INFO(p.x << ", " << p.y << ", " << p.z << ": depth " << clip.z / clip.w);
    REQUIRE(clip.w > 0);
    CHECK(clip.z / clip.w >= -1);
    CHECK(clip.z / clip.w <= 1);
  }
}

TEST_CASE("a camera's clip planes follow the terrain beside the eye, not its target",
          "[viewer][camera]") {
  // (The near plane was 1e-4 of the distance to the target: a target 1e6 away clipped the
  // terrain under the eye, a blank image with exit 0; at 2e19 the camera became NaN.)
  const std::string dir = test::TempDir();
  std::string flat;  // y = 0 over [-10, 10] x [-10, 10], normals up (drawn 128, 255, 128)
  for (int k = 0; k <= 100; ++k) {
    for (int i = 0; i <= 100; ++i)
      flat += std::to_string(-10 + i * 0.2) + " 0 " + std::to_string(-10 + k * 0.2) + " 0 1 0\n";
  }
  test::WriteFile(dir + "/flat.pts", flat);
  // The same eye, half a unit above the ground, looking the same way at ever farther targets.
  auto shoot = [&](const std::string& target, json* state) {
    const std::string shot = dir + "/shot.png";
    const RunResult r =
        View({"--terrain", dir + "/flat.pts", "--camera", "0 0.5 0 " + target, "--size", "320x200",
              "--screenshot", shot, "--dump-state", dir + "/state.json"});
    INFO("target " << target << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    *state = json::parse(test::ReadFile(dir + "/state.json"));
    return CountColor(ReadPng(shot), {128, 255, 128});
  };
  json state;
  const int near_target = shoot("10 0 10", &state);
  INFO("terrain pixels with the target 10 away: " << near_target);
  REQUIRE(near_target > 320 * 200 / 4);
  for (const std::string target : {"1e6 0 1e6", "1e15 0 1e15"}) {
    const int far_target = shoot(target, &state);
    INFO("target " << target << ": " << far_target << " terrain pixels");
    CHECK(far_target > near_target * 8 / 10);
    // The eye stays where it was put.
    CHECK(state["camera"]["eye"] == json::array({0.0, 0.5, 0.0}));
  }
  CHECK(state["camera"]["target"][0].get<double>() == 1e15);
  // A query far from the terrain: its box put the near plane past the terrain (and the scene's
  // origin beside it, the terrain's float vertices 64 units apart): a blank image, exit 0.
  for (const std::string far : {"snap 1e9 0 0", "snap -1e6 0 0"}) {
    const std::string shot = dir + "/far_query.png";
    const RunResult r = View({"--terrain", dir + "/flat.pts", "--camera", "0 0.5 0 10 0 10",
                              "--query", far, "--size", "320x200", "--screenshot", shot});
    INFO(far << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(CountColor(ReadPng(shot), {128, 255, 128}) > near_target * 8 / 10);
  }
  // An eye 1e15 away still looks at its target: the query there is drawn at the centre (eye +
  // the view direction rounded by 0.125, turning the view up to 5 degrees: 18 px off).
  const RunResult aimed = View({"--terrain", dir + "/flat.pts", "--camera", "1e15 7e14 3e14 2 0 2",
                                "--query", "snap 2 0 2", "--size", "800x600", "--screenshot",
                                dir + "/aimed.png", "--dump-state", dir + "/aimed.json"});
  INFO(aimed.err);
  REQUIRE(aimed.exit_code == 0);
  const json at = json::parse(test::ReadFile(dir + "/aimed.json"));
  REQUIRE(at["queries"].size() == 1);
  CHECK(std::fabs(at["queries"][0]["pixel"][0].get<double>() - 400) < 1);
  CHECK(std::fabs(at["queries"][0]["pixel"][1].get<double>() - 300) < 1);
  // Beyond what a query may reach, the camera is refused.
  const RunResult r = View({"--terrain", dir + "/flat.pts", "--camera", "0 0.5 0 2e19 0 2e19",
                            "--screenshot", dir + "/refused.png"});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--camera: expected the eye and the target within +-1e15"));
  // An eye and a target apart in world space but one point about the scene's centre (the
  // hills': 20 away): a blank image and exit 0.
  const RunResult same = View({"--terrain", kTerrain, "--camera", "0 5 0 1e-15 5 1e-15",
                               "--screenshot", dir + "/refused.png"});
  CHECK(same.exit_code == 2);
  CHECK_THAT(same.err, Catch::Contains("--camera: the eye and the target are too near each other"));
  std::ifstream none(dir + "/refused.png");
  CHECK_FALSE(none.good());
}

TEST_CASE("height colouring and grid cells change the picture", "[viewer][screenshot]") {
  const std::string dir = test::TempDir();
  REQUIRE(View({"--terrain", kTerrain, "--height-colors", "--cells", "--size", "320x200",
                "--screenshot", dir + "/h.png"})
              .exit_code == 0);
  const Image image = ReadPng(dir + "/h.png");
  REQUIRE(image.width == 320);
  // No green-dominant normal colours now; the height ramp's blues and sands instead.
  int normal_green = 0, other = 0;
  for (int y = 30; y < 170; ++y) {
    for (int x = 0; x < 320; ++x) {
      const glm::ivec3 c = image.At(x, y);
      if (c.x == 128 && c.y > 240 && c.z == 128) ++normal_green;
      if (!Near(c, {28, 30, 36}, 3)) ++other;
    }
  }
  CHECK(normal_green < 50);
  CHECK(other > 320 * 140 / 8);  // the terrain, framed clear of the overlay's bands
}

// hills.pts turned so that its up is +z: (x, y, z) -> (x, -z, y), normals alike.
std::string ZUpHills() {
  std::ifstream in(kTerrain);
  std::ostringstream out;
  out.precision(17);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double v[6];
    for (double& x : v) fields >> x;
    out << v[0] << ' ' << -v[2] << ' ' << v[1] << ' ' << v[3] << ' ' << -v[5] << ' ' << v[4]
        << '\n';
  }
  return out.str();
}

TEST_CASE("a Z-up terrain seen with --up z is the picture of its Y-up twin", "[viewer][up]") {
  // (The view stood on +y whatever the data: a Z-up terrain was drawn on its side, its height
  // colours running across it.)
  const std::string dir = test::TempDir();
  for (const char* sub : {"/y", "/z"}) std::filesystem::create_directory(dir + sub);
  test::WriteFile(dir + "/y/hills.pts", test::ReadFile(kTerrain));
  test::WriteFile(dir + "/z/hills.pts", ZUpHills());
  const std::vector<std::string> common = {"--height-colors", "--size", "320x200"};
  auto shoot = [&](const std::string& terrain, std::vector<std::string> flags,
                   const std::string& name) {
    flags.insert(flags.end(), {"--terrain", terrain, "--screenshot", dir + "/" + name + ".png",
                               "--dump-state", dir + "/" + name + ".json"});
    flags.insert(flags.end(), common.begin(), common.end());
    REQUIRE(View(flags).exit_code == 0);
    return ReadPng(dir + "/" + name + ".png");
  };
  const Image y = shoot(dir + "/y/hills.pts", {}, "y");
  // Below the overlay's first line (the file's name): every pixel the same.
  auto differing = [&](const Image& other) {
    int count = 0;
    for (int row = 16; row < y.height; ++row) {
      for (int x = 0; x < y.width; ++x) count += y.At(x, row) != other.At(x, row);
    }
    return count;
  };
  for (const char* up : {"z", "0,0,1", "Z", "0,0,2.5"}) {
    INFO("--up " << up);
    CHECK(differing(shoot(dir + "/z/hills.pts", {"--up", up}, "z")) == 0);
    const json state = json::parse(test::ReadFile(dir + "/z.json"));
    CHECK(state["camera"]["up"] == json::array({0.0, 0.0, 1.0}));
  }
  // Seen Y-up, the same samples differ (the check above could fail).
  CHECK(differing(shoot(dir + "/z/hills.pts", {}, "side")) > 1000);
}

TEST_CASE("queries and the camera follow --up", "[viewer][up]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/z.pts", ZUpHills());
  // hills.pts' "next 10 1 10 1.2 0 0.3", turned; the dumped camera projects the chosen sample
  // where it is drawn, with the dumped up.
  const RunResult r =
      View({"--terrain", dir + "/z.pts", "--up", "z", "--query", "next 10 -10 1 1.2 -0.3 0",
            "--size", "320x200", "--screenshot", dir + "/q.png", "--dump-state", dir + "/q.json"});
  REQUIRE(r.exit_code == 0);
  const json state = json::parse(test::ReadFile(dir + "/q.json"));
  const json& q = state["queries"][0];
  REQUIRE(q["found"] == true);
  const json& c = state["camera"];
  auto vec = [](const json& v) {
    return glm::dvec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
  };
  const glm::dmat4 view = glm::lookAt(vec(c["eye"]), vec(c["target"]), vec(c["up"]));
  const glm::dmat4 proj = glm::perspective(glm::radians(45.0), 320.0 / 200, 0.1, 1000.0);
  const glm::dvec4 clip = proj * view * glm::dvec4(vec(q["point"]), 1);
  const glm::vec2 px(static_cast<float>((clip.x / clip.w * 0.5 + 0.5) * 320),
                     static_cast<float>((0.5 - clip.y / clip.w * 0.5) * 200));
  CHECK(std::abs(px.x - q["pixel"][0].get<float>()) < 1);
  CHECK(std::abs(px.y - q["pixel"][1].get<float>()) < 1);
  CHECK(CountColorNear(ReadPng(dir + "/q.png"), px, 6, kChosen) > 10);
  // Above the terrain along +z: the eye's z beyond the target's.
  CHECK(c["eye"][2].get<double>() > c["target"][2].get<double>());
}

TEST_CASE("a --camera straight along the up is tilted, and said", "[viewer][up]") {
  // (The eye moved without a word: straight down onto a Z-up terrain.)
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/z.pts", ZUpHills());
  RunResult r = View({"--terrain", dir + "/z.pts", "--up", "z", "--camera", "20 -20 30 20 -20 0",
                      "--size", "160x100", "--screenshot", dir + "/c.png"});
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("note: --camera looks within a degree of straight along the "
                                    "up; the eye is tilted to 89 degrees about the target"));
  // Looking down at 45 degrees: kept, and nothing said; a leading '+' read as --query reads it.
  r = View({"--terrain", dir + "/z.pts", "--up", "z", "--camera", "+20 -40 +20 20 -20 0", "--size",
            "160x100", "--screenshot", dir + "/c.png", "--dump-state", dir + "/c.json"});
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.err, !Catch::Contains("--camera"));
  CHECK(json::parse(test::ReadFile(dir + "/c.json"))["camera"]["eye"] ==
        json::array({20.0, -40.0, 20.0}));
}

TEST_CASE("a height map stood up along --up-axis is seen standing on it", "[viewer][up]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/g.asc",
                  "ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
                  "0 1 2 3\n1 2 3 4\n2 3 4 5\n");
  for (const char* axis : {"x", "y", "z"}) {
    const RunResult r = View({"--terrain", dir + "/g.asc", "--up-axis", axis, "--size", "160x100",
                              "--screenshot", dir + "/g.png", "--dump-state", dir + "/g.json"});
    INFO(axis);
    REQUIRE(r.exit_code == 0);
    const json up = json::parse(test::ReadFile(dir + "/g.json"))["camera"]["up"];
    const int i = axis[0] - 'x';
    CHECK(up[static_cast<size_t>(i)] == 1.0);
    CHECK(up[static_cast<size_t>((i + 1) % 3)] == 0.0);
    CHECK(up[static_cast<size_t>((i + 2) % 3)] == 0.0);
  }
  // --up wins over --up-axis.
  const RunResult r =
      View({"--terrain", dir + "/g.asc", "--up-axis", "z", "--up", "-y", "--size", "160x100",
            "--screenshot", dir + "/g.png", "--dump-state", dir + "/g.json"});
  REQUIRE(r.exit_code == 0);
  CHECK(json::parse(test::ReadFile(dir + "/g.json"))["camera"]["up"] ==
        json::array({0.0, -1.0, 0.0}));
}

std::string WalkJson() {
  // L1 steps from (2, 0, 2) over an arc to (4, 0, 2) during frames 1-13; R1 from (2, 0, 0)
  // to (4, 0, 0) during frames 13-25. The body moves along x between them.
  return R"({"format": "footfall-walk", "version": 1, "fps": 24, "tracks": [
    {"name": "L1", "kind": "foot", "keys": [
      {"frame": 1, "phase": "start", "position": [2, 0, 2], "normal": [0, 1, 0]},
      {"frame": 7, "phase": "mid", "position": [3, 0.5, 2], "normal": [0, 1, 0]},
      {"frame": 13, "phase": "end", "position": [4, 0, 2], "normal": [0, 1, 0]}]},
    {"name": "R1", "kind": "foot", "keys": [
      {"frame": 13, "phase": "start", "position": [2, 0, 0], "normal": [0, 1, 0]},
      {"frame": 19, "phase": "mid", "position": [3, 0.5, 0], "normal": [0, 1, 0]},
      {"frame": 25, "phase": "end", "position": [4, 0, 0], "normal": [0, 1, 0]}]},
    {"name": "body", "kind": "body", "keys": [
      {"frame": 1, "position": [2, 1, 1], "rotation": [0, 0, 0, 1]},
      {"frame": 25, "position": [4, 1, 1], "rotation": [0, 0, 0, 2]}]}]})";
}

// A valid walk but for L1's second key, which comes before its first.
std::string DescendingWalkJson() {
  return R"({"format": "footfall-walk", "version": 1, "fps": 24, "tracks": [
    {"name": "L1", "kind": "foot", "keys": [
      {"frame": 5, "phase": "start", "position": [0, 0, 0]},
      {"frame": 2, "phase": "end", "position": [1, 0, 0]}]}]})";
}

// The pixel of `state`'s dumped camera (eye, target) for world point p, by the test's own
// projection.
glm::vec2 ProjectWithDumpedCamera(const json& state, const glm::dvec3& p) {
  const json& c = state["camera"];
  const glm::dvec3 eye(c["eye"][0].get<double>(), c["eye"][1].get<double>(),
                       c["eye"][2].get<double>());
  const glm::dvec3 target(c["target"][0].get<double>(), c["target"][1].get<double>(),
                          c["target"][2].get<double>());
  return Project(eye, target, state["image"]["width"].get<int>(),
                 state["image"]["height"].get<int>(), p);
}

TEST_CASE("framing takes in a query's candidate ring", "[viewer][camera]") {
  // (The terrain and the query's points were framed: a ring reaching beyond them was cut off
  // at the image's edge.)
  const std::string dir = test::TempDir();
  const int width = 640, height = 400;
  const RunResult r =
      View({"--terrain", kTerrain, "--query", "next 20 0 20 30 0 0", "--size", "640x400",
            "--screenshot", dir + "/shot.png", "--dump-state", dir + "/state.json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  REQUIRE(state["queries"].size() == 1);
  const double radius = state["queries"][0]["radius"].get<double>();
  CHECK(radius == Approx(30));
  const glm::dvec3 ideal(50, 0, 20);
  for (int i = 0; i < 48; ++i) {
    const double a = 6.283185307179586 * i / 48;
    const glm::vec2 px =
        ProjectWithDumpedCamera(state, ideal + radius * glm::dvec3(std::cos(a), 0, std::sin(a)));
    INFO("ring point " << i << " at " << px.x << ", " << px.y);
    CHECK(px.x >= 0);
    CHECK(px.x < width);
    CHECK(px.y >= 0);
    CHECK(px.y < height);
  }
}

TEST_CASE("framing leaves the overlay's bands clear", "[viewer][camera]") {
  // (The bounding sphere filled the whole height: a column 20 m tall on a 2 m floor reached
  // under the line of text at the top.)
  const std::string dir = test::TempDir();
  std::string tall;  // a 2 x 2 m floor with a column 20 m tall at its centre
  for (int k = 0; k <= 20; ++k) {
    for (int i = 0; i <= 20; ++i)
      tall += std::to_string(i * 0.1) + " 0 " + std::to_string(k * 0.1) + " 0 1 0\n";
  }
  for (int j = 0; j <= 200; ++j) tall += "1 " + std::to_string(j * 0.1) + " 1 1 0 0\n";
  test::WriteFile(dir + "/tall.pts", tall);
  for (const std::string size : {"640x400", "320x480"}) {
    const RunResult r = View({"--terrain", dir + "/tall.pts", "--size", size, "--screenshot",
                              dir + "/shot.png", "--dump-state", dir + "/state.json"});
    INFO(size << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/state.json"));
    const int width = state["image"]["width"], height = state["image"]["height"];
    // The info line's band at the top (its line of 12 px and 6 px more), the help lines' at
    // the bottom (from 4 px above their first line).
    const json& hud = state["hud"];
    REQUIRE(hud.size() >= 2);
    const double top_band = hud[0]["y"].get<double>() + 14;
    double bottom_band = height;
    for (const json& line : hud) {
      if (line["y"].get<double>() > height / 2.0)
        bottom_band = std::min(bottom_band, line["y"].get<double>() - 4);
    }
    for (const glm::dvec3 p : {glm::dvec3(1, 20, 1), glm::dvec3(0, 0, 0), glm::dvec3(2, 0, 0),
                               glm::dvec3(0, 0, 2), glm::dvec3(2, 0, 2)}) {
      const glm::vec2 px = ProjectWithDumpedCamera(state, p);
      INFO("(" << p.x << ", " << p.y << ", " << p.z << ") at " << px.x << ", " << px.y
               << "; bands end at " << top_band << " and begin at " << bottom_band);
      CHECK(px.y > top_band);
      CHECK(px.y < bottom_band);
      CHECK(px.x > 0);
      CHECK(px.x < width);
    }
  }
}

TEST_CASE("a terrain a billionth the size is drawn as the same picture", "[viewer][camera]") {
  // (Point sizes stopped growing at a camera distance of 1e-6: at 1e-9 scale a solid grid of
  // samples was drawn as scattered one-pixel dots.)
  const std::string dir = test::TempDir();
  std::vector<int> lit;
  for (const double scale : {1.0, 1e-9}) {
    std::ostringstream grid;
    grid.precision(17);
    for (int k = 0; k < 20; ++k) {
      for (int i = 0; i < 20; ++i)
        grid << i * 0.1 * scale << " 0 " << k * 0.1 * scale << " 0 1 0\n";
    }
    test::WriteFile(dir + "/grid.pts", grid.str());
    const RunResult r = View(
        {"--terrain", dir + "/grid.pts", "--size", "320x240", "--screenshot", dir + "/grid.png"});
    INFO(scale << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const Image image = ReadPng(dir + "/grid.png");
    int count = 0;
    for (int y = image.height / 4; y < image.height * 3 / 4; ++y) {
      for (int x = 0; x < image.width; ++x) count += !Near(image.At(x, y), {28, 30, 36}, 3);
    }
    lit.push_back(count);
  }
  INFO("lit pixels at scale 1: " << lit[0] << ", at 1e-9: " << lit[1]);
  CHECK(lit[0] > 2000);
  CHECK(std::abs(lit[1] - lit[0]) < lit[0] / 20);
}

TEST_CASE("a window too small for the overlay still shows the terrain", "[viewer][camera]") {
  // At 300 x 80 and 100 x 100 the overlay's bands met and no terrain was drawn (exit 0), and
  // a line of text was placed above the window.
  const std::string dir = test::TempDir();
  for (const std::string size : {"300x80", "100x100", "160x120"}) {
    const RunResult r = View({"--terrain", kTerrain, "--size", size, "--screenshot",
                              dir + "/small.png", "--dump-state", dir + "/state.json"});
    INFO(size << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/state.json"));
    const int height = state["image"]["height"];
    for (const json& line : state["hud"]) {
      CHECK(line["y"].get<double>() >= 0);
      CHECK(line["y"].get<double>() + 12 <= height);
    }
    // The terrain fills much of the middle rows: not the background colour.
    const Image image = ReadPng(dir + "/small.png");
    int terrain = 0, pixels = 0;
    for (int y = image.height * 3 / 8; y < image.height * 5 / 8; ++y) {
      for (int x = 0; x < image.width; ++x, ++pixels)
        terrain += !Near(image.At(x, y), {28, 30, 36}, 3);
    }
    CHECK(terrain > pixels / 10);
  }
}

TEST_CASE("markers shrink in a tiny window and leave the terrain in view", "[viewer][walk]") {
  // Markers of a fixed pixel size covered a 7 x 3 screenshot whole, and most of 60 x 40.
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/walk.json", WalkJson());
  for (const std::string size : {"60x40", "24x24"}) {
    INFO(size);
    const RunResult bare =
        View({"--terrain", kTerrain, "--size", size, "--screenshot", dir + "/bare.png"});
    REQUIRE(bare.exit_code == 0);
    const RunResult walk = View({"--terrain", kTerrain, "--walk", dir + "/walk.json", "--frame",
                                 "13", "--size", size, "--screenshot", dir + "/walk.png"});
    INFO(walk.err);
    REQUIRE(walk.exit_code == 0);
    const Image a = ReadPng(dir + "/bare.png"), b = ReadPng(dir + "/walk.png");
    REQUIRE((a.width == b.width && a.height == b.height));
    int changed = 0;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) changed += !Near(a.At(x, y), b.At(x, y), 3);
    INFO(changed << " of " << a.width * a.height << " pixels changed by the walk");
    CHECK(changed > 0);                            // the walk is drawn
    CHECK(changed < a.width * a.height * 3 / 10);  // and leaves most of the terrain
  }
}

TEST_CASE("scenes a few centimetres across are framed to their size", "[viewer][camera]") {
  // (Framing took a radius of at least 0.5 m: a terrain or a walk of 4 cm was a dot.)
  const std::string dir = test::TempDir();
  SECTION("a terrain 4 cm across, sampled every 2 mm") {
    std::string tiny;  // y = 0, normals up (drawn 128, 255, 128)
    for (int k = 0; k <= 20; ++k) {
      for (int i = 0; i <= 20; ++i)
        tiny += std::to_string(i * 0.002) + " 0 " + std::to_string(k * 0.002) + " 0 1 0\n";
    }
    test::WriteFile(dir + "/tiny.pts", tiny);
    const RunResult r =
        View({"--terrain", dir + "/tiny.pts", "--size", "320x200", "--screenshot", dir + "/t.png"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const int terrain = CountColor(ReadPng(dir + "/t.png"), {128, 255, 128});
    INFO("terrain pixels: " << terrain);
    CHECK(terrain > 320 * 200 / 20);  // (it was a dot)
  }
  SECTION("a walk 2 cm long") {
    std::string walk = WalkJson();  // scaled by 1/100: feet 2 cm apart, stepping 2 cm
    for (const auto& [from, to] :
         std::vector<std::pair<std::string, std::string>>{{"[2, 0, 2]", "[0.02, 0, 0.02]"},
                                                          {"[3, 0.5, 2]", "[0.03, 0.005, 0.02]"},
                                                          {"[4, 0, 2]", "[0.04, 0, 0.02]"},
                                                          {"[2, 0, 0]", "[0.02, 0, 0]"},
                                                          {"[3, 0.5, 0]", "[0.03, 0.005, 0]"},
                                                          {"[4, 0, 0]", "[0.04, 0, 0]"},
                                                          {"[2, 1, 1]", "[0.02, 0.01, 0.01]"},
                                                          {"[4, 1, 1]", "[0.04, 0.01, 0.01]"}}) {
      REQUIRE(walk.find(from) != std::string::npos);
      walk.replace(walk.find(from), from.size(), to);
    }
    test::WriteFile(dir + "/walk.json", walk);
    const RunResult r = View({"--walk", dir + "/walk.json", "--size", "640x400", "--screenshot",
                              dir + "/w.png", "--dump-state", dir + "/w.json"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/w.json"));
    const json& tracks = state["walk"]["tracks"];
    const glm::vec2 l1(tracks[0]["pixel"][0].get<float>(), tracks[0]["pixel"][1].get<float>());
    const glm::vec2 r1(tracks[1]["pixel"][0].get<float>(), tracks[1]["pixel"][1].get<float>());
    INFO("L1 at " << l1.x << "," << l1.y << "  R1 at " << r1.x << "," << r1.y);
    CHECK(tracks[0]["visible"] == true);
    CHECK(tracks[1]["visible"] == true);
    CHECK(glm::length(l1 - r1) > 40);
    // The body's axes are sized after the walk, not 16 cm long across the picture.
    const Image image = ReadPng(dir + "/w.png");
    const int axes = CountColor(image, {255, 60, 60}) + CountColor(image, {60, 255, 60}) +
                     CountColor(image, {60, 60, 255});
    INFO("body axes pixels: " << axes);
    CHECK(axes < 40);
  }
}

TEST_CASE("the state dump names each track's character in a crowd", "[viewer][walk]") {
  // (Two characters' tracks were dumped as L1, body, L1, body: pixels could not be told apart.)
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/crowd.json", R"({"format": "footfall-walk", "version": 1, "fps": 24,
    "tracks": [
    {"name": "L1", "kind": "foot", "character": "c1", "keys": [
      {"frame": 1, "phase": "start", "position": [0, 0, 0], "normal": [0, 1, 0]}]},
    {"name": "body", "kind": "body", "character": "c1", "keys": [
      {"frame": 1, "position": [0, 1, 0], "rotation": [0, 0, 0, 1]}]},
    {"name": "L1", "kind": "foot", "character": "c2", "keys": [
      {"frame": 1, "phase": "start", "position": [2, 0, 0], "normal": [0, 1, 0]}]},
    {"name": "body", "kind": "body", "character": "c2", "keys": [
      {"frame": 1, "position": [2, 1, 0], "rotation": [0, 0, 0, 1]}]}]})");
  const RunResult r = View({"--walk", dir + "/crowd.json", "--size", "160x100", "--screenshot",
                            dir + "/crowd.png", "--dump-state", dir + "/state.json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  std::vector<std::string> named;
  for (const json& t : state["walk"]["tracks"])
    named.push_back(t.value("character", std::string("?")) + "/" + t["name"].get<std::string>());
  CHECK(named == std::vector<std::string>{"c1/L1", "c1/body", "c2/L1", "c2/body"});
}

TEST_CASE("screenshot of a walk shows the feet where the JSON puts them at that frame",
          "[viewer][walk]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/walk.json", WalkJson());
  const glm::dvec3 eye(3, 6, 7), target(3, 0, 1);
  const glm::ivec3 left(255, 80, 40), right(40, 130, 255);  // foot tracks 0 and 1
  struct Case {
    int frame;
    glm::dvec3 l1, r1;
  };
  for (const Case& c : {Case{13, {4, 0, 2}, {2, 0, 0}}, Case{7, {3, 0.5, 2}, {2, 0, 0}},
                        Case{25, {4, 0, 2}, {4, 0, 0}}}) {
    SECTION("frame " + std::to_string(c.frame)) {
      const std::string shot = dir + "/walk" + std::to_string(c.frame) + ".png";
      const RunResult r = View({"--walk", dir + "/walk.json", "--frame", std::to_string(c.frame),
                                "--camera", "3 6 7 3 0 1", "--size", "640x480", "--screenshot",
                                shot, "--dump-state", dir + "/state.json"});
      REQUIRE(r.exit_code == 0);
      const Image image = ReadPng(shot);
      REQUIRE(image.width == 640);
      const glm::vec2 l = Project(eye, target, 640, 480, c.l1);
      const glm::vec2 rr = Project(eye, target, 640, 480, c.r1);
      INFO("L1 at " << l.x << "," << l.y << "  R1 at " << rr.x << "," << rr.y);
      CHECK(CountColorNear(image, l, 4, left) >= 40);
      CHECK(CountColorNear(image, rr, 4, right) >= 40);
      const json state = json::parse(test::ReadFile(dir + "/state.json"));
      CHECK(state["walk"]["frame"] == c.frame);
      CHECK(state["walk"]["tracks"][0]["name"] == "L1");
      CHECK(state["walk"]["tracks"][0]["position"][0].get<double>() == Approx(c.l1.x));
      CHECK(state["walk"]["tracks"][0]["position"][1].get<double>() == Approx(c.l1.y));
      // The file's last body rotation is [0, 0, 0, 2]: drawn as the unit quaternion.
      CHECK(state["walk"]["tracks"][2]["kind"] == "body");
      CHECK(state["walk"]["tracks"][2]["rotation"][3].get<double>() == Approx(1));
    }
  }
}

TEST_CASE("a foot that carries rotations is posed with them, one without has none",
          "[viewer][walk]") {
  // (--foot-rotations walks: the feet's orientations were read and then not shown.)
  const std::string dir = test::TempDir();
  const double s = std::sqrt(0.5);
  test::WriteFile(dir + "/turned.json", R"({"format": "footfall-walk", "version": 1, "fps": 24,
    "tracks": [
    {"name": "L", "kind": "foot", "keys": [
      {"frame": 1, "phase": "end", "position": [0, 0, 0], "normal": [0, 1, 0],
       "rotation": [0, 0, 0, 1]},
      {"frame": 11, "phase": "end", "position": [0, 0, 1], "normal": [0, 1, 0],
       "rotation": [0, 1, 0, 1]}]},
    {"name": "R", "kind": "foot", "keys": [
      {"frame": 1, "phase": "end", "position": [1, 0, 0], "normal": [0, 1, 0]}]}]})");
  struct Case {
    int frame;
    double y, w;  // the foot's rotation: a turn about Y
  };
  const double quarter = std::sin(M_PI / 8), quarter_w = std::cos(M_PI / 8);
  for (const Case& c : {Case{1, 0, 1}, Case{6, quarter, quarter_w}, Case{11, s, s}}) {
    INFO("frame " << c.frame);
    const RunResult r =
        View({"--walk", dir + "/turned.json", "--frame", std::to_string(c.frame), "--size",
              "160x100", "--screenshot", dir + "/turned.png", "--dump-state", dir + "/state.json"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/state.json"));
    const json& feet = state["walk"]["tracks"];
    REQUIRE(feet[0]["rotation"].size() == 4);
    CHECK(feet[0]["rotation"][0].get<double>() == Approx(0).margin(1e-12));
    CHECK(feet[0]["rotation"][1].get<double>() == Approx(c.y).margin(1e-12));
    CHECK(feet[0]["rotation"][3].get<double>() == Approx(c.w).margin(1e-12));
    CHECK_FALSE(feet[1].contains("rotation"));
  }
  // Drawn: the foot's forward is a line from it (close up, beside its normal), which the same
  // walk without rotations lacks.
  std::string plain = test::ReadFile(dir + "/turned.json");
  for (const char* q : {R"(,
       "rotation": [0, 0, 0, 1])",
                        R"(,
       "rotation": [0, 1, 0, 1])"})
    plain.erase(plain.find(q), std::string(q).size());
  // (The same file, the overlay showing its path: turned first, then plain.)
  Image shots[2];
  for (int i = 0; i < 2; ++i) {
    if (i == 1) test::WriteFile(dir + "/turned.json", plain);
    const RunResult r =
        View({"--walk", dir + "/turned.json", "--frame", "1", "--size", "320x240", "--camera",
              "0.06 0.08 -0.06 0 0 0.01", "--screenshot", dir + "/close.png"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    shots[i] = ReadPng(dir + "/close.png");
  }
  REQUIRE(shots[0].rgb.size() == shots[1].rgb.size());
  int differ = 0;
  for (int y = 0; y < shots[0].height; ++y)
    for (int x = 0; x < shots[0].width; ++x) differ += shots[0].At(x, y) != shots[1].At(x, y);
  CHECK(differ >= 30);
}

TEST_CASE(
    "soles (the walk's foot_length, --foot-length) are drawn at each foot's pose and at "
    "its footholds",
    "[viewer][walk]") {
  // WalkJson's body faces +Z: at frame 1, L1 stands at (2, 0, 2) with its sole from z 1.6 to
  // 2.4 (0.8 long) and x 2 -+ 0.133 (a third as wide); its next foothold is (4, 0, 2).
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/walk.json", WalkJson());
  const glm::dvec3 eye(3, 6, 7), target(3, 0, 1);
  const glm::ivec3 left(255, 80, 40), dim_left(167, 80, 60);  // L1, and its dimmed colour
  auto shot = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {
        "--walk",       dir + "/walk.json", "--frame",      "1",
        "--camera",     "3 6 7 3 0 1",      "--size",       "640x480",
        "--screenshot", dir + "/sole.png",  "--dump-state", dir + "/state.json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = View(args);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    return ReadPng(dir + "/sole.png");
  };
  const double side = 2 + 0.8 / 6;
  const glm::vec2 sole_edge = Project(eye, target, 640, 480, {side, 0, 2.25});
  const glm::vec2 footprint_edge = Project(eye, target, 640, 480, {4 + 0.8 / 6, 0, 2.25});
  INFO("sole edge at " << sole_edge.x << "," << sole_edge.y << ", footprint edge at "
                       << footprint_edge.x << "," << footprint_edge.y);
  const Image plain = shot({});
  CHECK(CountColorNear(plain, sole_edge, 2, left) == 0);
  CHECK(CountColorNear(plain, footprint_edge, 2, dim_left) == 0);
  const Image soles = shot({"--foot-length", "0.8"});
  CHECK(CountColorNear(soles, sole_edge, 2, left) > 0);
  CHECK(CountColorNear(soles, footprint_edge, 2, dim_left) > 0);
  // Feet without rotations of their own are turned as --foot-rotations turns them.
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  REQUIRE(state["walk"]["tracks"][0].contains("rotation"));
  CHECK(state["walk"]["tracks"][0]["rotation"][3].get<double>() == Approx(1));

  // A walk whose foot tracks carry their foot_length (as footfall generate writes a character
  // with one) draws those soles unasked; --foot-length 0 draws none, and a length given
  // replaces the walk's.
  std::string own = WalkJson();
  own.replace(own.find(R"("kind": "foot")"), 14, R"("kind": "foot", "foot_length": 0.8)");
  test::WriteFile(dir + "/walk.json", own);
  // (--dump-state gives each foot's sole_length where a sole is drawn: here L1's alone.)
  auto sole_lengths = [&dir]() {
    const json tracks = json::parse(test::ReadFile(dir + "/state.json"))["walk"]["tracks"];
    return std::vector<double>{tracks[0].value("sole_length", 0.0),
                               tracks[1].value("sole_length", 0.0)};
  };
  const Image walk_soles = shot({});
  CHECK(CountColorNear(walk_soles, sole_edge, 2, left) > 0);
  CHECK(CountColorNear(walk_soles, footprint_edge, 2, dim_left) > 0);
  CHECK(sole_lengths() == std::vector<double>{0.8, 0});
  const Image off = shot({"--foot-length", "0"});
  CHECK(CountColorNear(off, sole_edge, 2, left) == 0);
  CHECK(CountColorNear(off, footprint_edge, 2, dim_left) == 0);
  CHECK(sole_lengths() == std::vector<double>{0, 0});
  const Image shorter = shot({"--foot-length", "0.2"});
  CHECK(CountColorNear(shorter, sole_edge, 2, left) == 0);
  CHECK(CountColorNear(shorter, footprint_edge, 2, dim_left) == 0);
  CHECK(sole_lengths() == std::vector<double>{0.2, 0.2});
  // A track's foot_width gives its sole's width (a third of the length without one).
  std::string wide = WalkJson();
  wide.replace(wide.find(R"("kind": "foot")"), 14,
               R"("kind": "foot", "foot_length": 0.8, "foot_width": 0.5)");
  test::WriteFile(dir + "/walk.json", wide);
  const glm::vec2 wide_edge = Project(eye, target, 640, 480, {2 + 0.25, 0, 2.25});
  const Image wide_soles = shot({});
  CHECK(CountColorNear(wide_soles, wide_edge, 2, left) > 0);
  CHECK(CountColorNear(wide_soles, sole_edge, 2, left) == 0);
  CHECK(CountColorNear(walk_soles, wide_edge, 2, left) == 0);
  const json wide_state = json::parse(test::ReadFile(dir + "/state.json"))["walk"]["tracks"][0];
  CHECK(wide_state.value("sole_width", 0.0) == 0.5);
  test::WriteFile(dir + "/walk.json", own);
  const RunResult none = View({"--foot-length", "0.2", "--screenshot", dir + "/sole.png"});
  CHECK(none.exit_code == 2);
  CHECK_THAT(none.err, Catch::Contains("--foot-length needs --walk"));
}

TEST_CASE("a walk's rotations with huge components are drawn as unit quaternions",
          "[viewer][walk]") {
  // (Squaring 1e300 overflowed: the rotation was normalised to zero, and the body drawn
  // without axes.)
  const std::string dir = test::TempDir();
  std::string walk = WalkJson();
  walk.replace(walk.find("[0, 0, 0, 1]"), 12, "[0, 0, 0, 1e300]");
  walk.replace(walk.find("[0, 0, 0, 2]"), 12, "[1e300, 0, 0, 1e300]");
  test::WriteFile(dir + "/walk.json", walk);
  for (const int frame : {1, 25}) {
    const RunResult r =
        View({"--walk", dir + "/walk.json", "--frame", std::to_string(frame), "--size", "160x100",
              "--screenshot", dir + "/shot.png", "--dump-state", dir + "/state.json"});
    INFO("frame " << frame << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/state.json"));
    const json& q = state["walk"]["tracks"][2]["rotation"];
    const double half = std::sqrt(0.5);
    CHECK(q[0].get<double>() == Approx(frame == 1 ? 0 : half).margin(1e-12));
    CHECK(q[1].get<double>() == Approx(0).margin(1e-12));
    CHECK(q[2].get<double>() == Approx(0).margin(1e-12));
    CHECK(q[3].get<double>() == Approx(frame == 1 ? 1 : half).margin(1e-12));
  }
}

TEST_CASE("a stopped walk's lines leave its feet and body clear in small windows",
          "[viewer][walk]") {
  // (The frame and "stopped" lines were not counted in the small-window rule: at 320 x 200 and
  // 400 x 180 they covered the feet and the body, where 320 x 180 showed them.)
  const std::string dir = test::TempDir();
  std::string walk = WalkJson();
  walk.replace(walk.find(R"("tracks")"), 0,
               R"("stopped": ")" + std::string(12, 'x') +
                   " step 3 of the walk: no way forward from the ledge's edge, every target "
                   "beyond the terrain's end, the feet kept where they stood and the body "
                   "over them, which the overlay must not cover\", ");
  test::WriteFile(dir + "/walk.json", walk);
  for (const std::string size : {"320x180", "320x200", "400x180", "320x240", "480x200"}) {
    const RunResult r =
        View({"--walk", dir + "/walk.json", "--frame", "13", "--size", size, "--screenshot",
              dir + "/shot.png", "--dump-state", dir + "/state.json"});
    INFO(size << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/state.json"));
    for (const json& track : state["walk"]["tracks"]) {
      const double px = track["pixel"][0], py = track["pixel"][1];
      for (const json& line : state["hud"]) {
        const double x = line["x"], y = line["y"], w = line["width"];
        INFO(track["name"] << " at " << px << ", " << py << "; line '" << line["text"] << "' at "
                           << x << ", " << y);
        CHECK_FALSE((px >= x && px <= x + w && py >= y - 2 && py <= y + 14));
      }
    }
  }
}

TEST_CASE("why a walk stopped is shown in full, wrapped to the window", "[viewer][walk]") {
  // (The reason ran off the right edge of the window in one line.)
  const std::string dir = test::TempDir();
  const std::string reason =
      "step 5: foot L at (0.8700, 1.2600, 2.3700): no foothold within 0.35 of (0.8700, 1.2600, "
      "2.8950) (the terrain ends, or rises as a wall at its bounds, before it) (6 more tries, "
      "shorter, longer or aimed down, refused too); walk stopped, keys up to step 4 kept";
  std::string walk = WalkJson();
  walk.replace(walk.find("\"fps\": 24,"), 10, "\"fps\": 24, \"stopped\": \"" + reason + "\",");
  test::WriteFile(dir + "/walk.json", walk);
  const int width = 480;
  const RunResult r = View({"--walk", dir + "/walk.json", "--size", "480x360", "--screenshot",
                            dir + "/shot.png", "--dump-state", dir + "/state.json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  std::string shown;  // the lines from "stopped: " on, joined again
  for (const json& line : state["hud"]) {
    const std::string text = line["text"];
    INFO("HUD line \"" << text << "\"");
    CHECK(line["x"].get<double>() >= 0);
    CHECK(line["x"].get<double>() + line["width"].get<double>() <= width - 6);
    if (!shown.empty()) {
      shown += " " + text;
    } else if (text.find("stopped: ") != std::string::npos) {
      shown = text.substr(text.find("stopped: "));
    }
  }
  CHECK(shown == "stopped: " + reason);
  // A window narrower than a character: wrapping looped, filling memory.
  const RunResult tiny =
      View({"--walk", dir + "/walk.json", "--size", "8x8", "--screenshot", dir + "/tiny.png"});
  INFO(tiny.err);
  CHECK(tiny.exit_code == 0);
}

TEST_CASE("overlay text draws a NUL or a character beyond ASCII as a question mark",
          "[viewer][text]") {
  // (The font stopped at a NUL, and looked bytes beyond ASCII up outside its table.)
  using viewer::DrawList;
  const std::string odd("ab\0c\xc3\xa9\x7f\xff", 8);  // NUL, e-acute in UTF-8, DEL, a stray byte
  DrawList drawn, expected, cut;
  drawn.Text(0, 0, odd, 1, {});
  expected.Text(0, 0, "ab?c???", 1, {});
  cut.Text(0, 0, "ab", 1, {});
  CHECK(drawn.triangles().size() == expected.triangles().size());
  CHECK(drawn.triangles().size() > cut.triangles().size());
  CHECK(DrawList::TextWidth(odd, 1) == DrawList::TextWidth("ab?c???", 1));
}

namespace {

// A viewer with `--terrain` hills (unless `terrain` is false) following footfalld at `address`
// until two queries arrive, then writing DIR/live.png and DIR/state.json; started, and seen
// following, when returned.
std::unique_ptr<test::Child> FollowLive(const std::string& address, const std::string& dir,
                                        const std::string& size, bool terrain = true) {
  std::vector<std::string> argv = {kView};
  if (terrain) argv.insert(argv.end(), {"--terrain", kTerrain});
  argv.insert(argv.end(),
              {"--server", address, "--live", "--live-wait", "2", "--timeout", "30", "--size", size,
               "--screenshot", dir + "/live.png", "--dump-state", dir + "/state.json"});
  auto viewer = std::make_unique<test::Child>(argv, std::vector<std::string>{test::XDisplay()});
  INFO("viewer stderr: " << viewer->Err());
  REQUIRE(viewer->WaitForOutput("live: following footfalld at " + address, kTimeout));
  return viewer;
}

}  // namespace

TEST_CASE("live: the viewer shows a query another client sends to footfalld", "[viewer][live]") {
  const std::string dir = test::TempDir();
  const LocalServer server(dir);
  INFO("footfalld stderr: " << server.child.Err());
  REQUIRE_FALSE(server.port.empty());
  const std::string& address = server.address;

  const std::unique_ptr<test::Child> viewer = FollowLive(address, dir, "640x400");
  INFO("viewer stderr: " << viewer->Err());

  // A next and a normal (footfall query sent normals as snaps: the viewer showed them so).
  const RunResult client = Run({FOOTFALL_CLI, "query", "--terrain", kTerrain, "--server", address},
                               {}, kTimeout, "next 10 1 10 1.2 0 0.3\nnormal 12 1 12\n");
  INFO("footfall query: " << client.out << client.err);
  REQUIRE(client.exit_code == 0);
  const json answer = json::parse(client.out.substr(0, client.out.find('\n')));
  REQUIRE(answer["found"] == true);

  int code = -1;
  REQUIRE(viewer->Wait(kTimeout, &code));
  REQUIRE(code == 0);
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  REQUIRE(state["live"]["received"].get<int>() >= 2);
  json q, normal;
  for (const json& live : state["live"]["queries"]) (live["op"] == "next" ? q : normal) = live;
  REQUIRE(q.is_object());
  REQUIRE(normal.is_object());
  CHECK(normal["op"] == "normal");
  CHECK(q["index"] == answer["index"]);
  CHECK(q["traced"] == true);  // re-traced on the local copy of the terrain
  REQUIRE(q["visible"] == true);
  const Image image = ReadPng(dir + "/live.png");
  const glm::vec2 pixel(q["pixel"][0].get<float>(), q["pixel"][1].get<float>());
  CHECK(CountColorNear(image, pixel, 4, kChosen) >= 40);
}

namespace {

// What a viewer with --terrain hills, following a footfalld, drew once `footfall query
// --terrain T` had sent `query` for each T of `terrains` in turn: its --dump-state and stderr.
struct LiveRun {
  json state;
  std::string viewer_err;
};
LiveRun FollowQueriesOn(const std::vector<std::string>& terrains, const std::string& query) {
  const std::string dir = test::TempDir();
  const LocalServer server(dir);
  INFO("footfalld stderr: " << server.child.Err());
  REQUIRE_FALSE(server.port.empty());
  const std::unique_ptr<test::Child> viewer = FollowLive(server.address, dir, "320x200");
  INFO("viewer stderr: " << viewer->Err());
  for (const std::string& terrain : terrains) {
    const RunResult client =
        Run({FOOTFALL_CLI, "query", "--terrain", terrain, "--server", server.address}, {}, kTimeout,
            query);
    INFO("footfall query: " << client.out << client.err);
    REQUIRE(client.exit_code == 0);
  }
  int code = -1;
  REQUIRE(viewer->Wait(kTimeout, &code));
  REQUIRE(code == 0);
  return {json::parse(test::ReadFile(dir + "/state.json")), viewer->Err()};
}

}  // namespace

TEST_CASE("live: a query on another terrain of footfalld is drawn untraced, with a note",
          "[viewer][live]") {
  // (Traced on the viewer's terrain, it showed that terrain's cells and candidates beside the
  // other terrain's answer, without a word.)
  const std::string stairs = std::string(FOOTFALL_DATA_DIR) + "/terrain/stairs.pts";
  const LiveRun run = FollowQueriesOn({stairs, kTerrain}, "snap 1 0.5 1\n");
  const json& queries = run.state["live"]["queries"];
  REQUIRE(queries.size() == 2);
  CHECK(queries[0]["other_terrain"] == true);  // the stairs'
  CHECK(queries[0]["traced"] == false);
  CHECK(queries[1]["other_terrain"] == false);  // the viewer's own terrain's
  CHECK(queries[1]["traced"] == true);
  CHECK_THAT(run.viewer_err, Catch::Contains("were asked on another terrain of the server"));
}

TEST_CASE("live: a screenshot frames the live queries it waited for beside the terrain",
          "[viewer][live]") {
  // A query on another terrain of the server, 500 m from the viewer's: the camera framed the
  // viewer's terrain alone, and the answer it waited for was out of the picture ("visible":
  // false), though F frames it in the window.
  const std::string far = test::TempDir() + "/far.pts";
  {
    std::ofstream out(far);
    for (int k = 0; k < 20; ++k)
      for (int i = 0; i < 20; ++i) out << 500 + 0.1 * i << " 0 " << 500 + 0.1 * k << " 0 1 0\n";
  }
  const LiveRun run = FollowQueriesOn({far, kTerrain}, "snap 501 0 501\n");
  const json& queries = run.state["live"]["queries"];
  REQUIRE(queries.size() == 2);
  CHECK(queries[0]["other_terrain"] == true);
  for (const json& q : queries) {
    INFO(q.dump());
    CHECK(q["visible"] == true);
  }
}

namespace {

// What a viewer with nothing loaded drew once `footfall query --terrain terrain` had sent
// `queries` to footfalld at `server`: its --dump-state and its screenshot.
struct LiveShot {
  json state;
  Image image;
};
LiveShot ShootLiveOnly(const LocalServer& server, const std::string& dir,
                       const std::string& terrain, const std::string& queries) {
  const std::unique_ptr<test::Child> viewer = FollowLive(server.address, dir, "640x400", false);
  INFO("viewer stderr: " << viewer->Err());
  const RunResult client =
      Run({FOOTFALL_CLI, "query", "--terrain", terrain, "--server", server.address}, {}, kTimeout,
          queries);
  INFO("footfall query: " << client.out << client.err);
  int code = -1;
  REQUIRE(viewer->Wait(kTimeout, &code));
  REQUIRE(code == 0);
  return {json::parse(test::ReadFile(dir + "/state.json")), ReadPng(dir + "/live.png")};
}

// Checks that live query q (from a --dump-state) is drawn, its chosen sample at its pixel.
void CheckChosenDrawn(const json& q, const Image& image) {
  INFO(q.dump());
  REQUIRE(q["visible"] == true);
  const glm::vec2 pixel(q["pixel"][0].get<float>(), q["pixel"][1].get<float>());
  CHECK(CountColorNear(image, pixel, 4, kChosen) >= 40);
}

}  // namespace

TEST_CASE("live: without a terrain, the picture is framed on the queries received",
          "[viewer][live]") {
  // (The camera framed the unit box at the origin before any query came: a blank picture.)
  const std::string dir = test::TempDir();
  const LocalServer server(dir);
  INFO("footfalld stderr: " << server.child.Err());
  REQUIRE_FALSE(server.port.empty());
  const LiveShot shot =
      ShootLiveOnly(server, dir, kTerrain, "next 10 1 10 1.2 0 0.3\nsnap 16 1 11\n");
  REQUIRE(shot.state["live"]["queries"].size() == 2);
  for (const json& q : shot.state["live"]["queries"]) {
    CHECK(q["found"] == true);
    CheckChosenDrawn(q, shot.image);
  }
}

TEST_CASE("live: a query footfalld refuses is not drawn, and the rest are framed",
          "[viewer][live]") {
  // (A refused query's point, 1e300 away, grew the drawn bounds: the camera went to NaN, and
  // the picture stayed blank for the session.)
  const std::string dir = test::TempDir();
  const LocalServer server(dir);
  INFO("footfalld stderr: " << server.child.Err());
  REQUIRE_FALSE(server.port.empty());
  const LiveShot shot = ShootLiveOnly(server, dir, kTerrain, "snap 1e300 0 0\nsnap 10 1 10\n");
  CHECK(shot.state["live"]["received"].get<int>() == 2);
  for (const json& v : shot.state["camera"]["eye"]) CHECK(v.is_number());
  REQUIRE(shot.state["live"]["queries"].size() == 1);
  CheckChosenDrawn(shot.state["live"]["queries"][0], shot.image);
}

TEST_CASE("live: without a terrain, queries at map coordinates are drawn where they are said to be",
          "[viewer][live]") {
  // (Render space stayed about the world's origin: a query near (5e5, 1, 5e6) was drawn from
  // floats half a unit apart, 55 pixels from the pixel --dump-state gave for it.)
  const std::string dir = test::TempDir();
  const std::string far = dir + "/far.pts";
  {
    std::ifstream in(kTerrain);
    std::ofstream out(far);
    out.precision(17);
    for (std::string line; std::getline(in, line);) {
      std::istringstream fields(line);
      double v[6];
      if (line.empty() || line[0] == '#' ||
          !(fields >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5]))
        continue;
      out << v[0] + 5e5 << ' ' << v[1] << ' ' << v[2] + 5e6 << ' ' << v[3] << ' ' << v[4] << ' '
          << v[5] << '\n';
    }
  }
  const LocalServer server(dir);
  INFO("footfalld stderr: " << server.child.Err());
  REQUIRE_FALSE(server.port.empty());
  const LiveShot shot =
      ShootLiveOnly(server, dir, far, "snap 500010.3 1 5000010.2\nsnap 500016.1 1 5000011.4\n");
  REQUIRE(shot.state["live"]["queries"].size() == 2);
  for (const json& q : shot.state["live"]["queries"]) CheckChosenDrawn(q, shot.image);
  // A --camera stays where it was put in the world when render space moves to the first query
  // (it moved with it, by the query's coordinates, and the query was out of the picture).
  test::Child aimed({kView, "--server", server.address, "--live", "--live-wait", "1", "--timeout",
                     "30", "--size", "320x200", "--camera", "500016 6 5000020 500010.3 1 5000010.2",
                     "--screenshot", dir + "/aimed.png", "--dump-state", dir + "/aimed.json"},
                    std::vector<std::string>{test::XDisplay()});
  INFO("viewer stderr: " << aimed.Err());
  REQUIRE(aimed.WaitForOutput("live: following footfalld at " + server.address, kTimeout));
  const RunResult again = Run({FOOTFALL_CLI, "query", "--terrain", far, "--server", server.address},
                              {}, kTimeout, "snap 500010.3 1 5000010.2\n");
  REQUIRE(again.exit_code == 0);
  int code = -1;
  REQUIRE(aimed.Wait(kTimeout, &code));
  REQUIRE(code == 0);
  const json aimed_state = json::parse(test::ReadFile(dir + "/aimed.json"));
  CHECK(aimed_state["camera"]["eye"] == json::array({500016.0, 6.0, 5000020.0}));
  CHECK(aimed_state["camera"]["target"] == json::array({500010.3, 1.0, 5000010.2}));
  REQUIRE(aimed_state["live"]["queries"].size() == 1);
  CHECK(aimed_state["live"]["queries"][0]["visible"] == true);
}

TEST_CASE("live: a server that never sees a query ends the wait with a message", "[viewer][live]") {
  const std::string dir = test::TempDir();
  const LocalServer server(dir);
  REQUIRE_FALSE(server.port.empty());
  const RunResult r = View({"--server", server.address, "--live", "--live-wait", "1", "--timeout",
                            "1", "--screenshot", dir + "/x.png"});
  CHECK(r.exit_code == 1);
  CHECK_THAT(r.err, Catch::Contains("received 0 of 1 queries"));
}

TEST_CASE("a walk drawn on a terrain it was not made on is pointed out", "[viewer][walk]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/walk.json", WalkJson());
  // A floor with a sample under every planted key of WalkJson(), and the same 100 units away.
  std::string here, there;
  for (int k = 0; k <= 12; ++k) {
    for (int i = 0; i <= 24; ++i) {
      here += std::to_string(i * 0.25) + " 0 " + std::to_string(k * 0.25) + " 0 1 0\n";
      there += std::to_string(100 + i * 0.25) + " 0 " + std::to_string(k * 0.25) + " 0 1 0\n";
    }
  }
  test::WriteFile(dir + "/here.pts", here);
  test::WriteFile(dir + "/there.pts", there);
  const std::string shot = dir + "/x.png";
  RunResult r =
      View({"--terrain", dir + "/here.pts", "--walk", dir + "/walk.json", "--screenshot", shot});
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.err, !Catch::Contains("warning"));
  r = View({"--terrain", dir + "/there.pts", "--walk", dir + "/walk.json", "--screenshot", shot});
  CHECK(r.exit_code == 0);  // still drawn
  CHECK_THAT(r.err, Catch::Contains("warning: 4 of 4 planted foot keys of " + dir +
                                    "/walk.json lie more than a grid cell"));
  CHECK_THAT(r.err, Catch::Contains("the walk was made on another terrain?"));
}

TEST_CASE("framing on the walk (--frame-walk) shows it large on a large terrain",
          "[viewer][camera]") {
  // A walk 2 m long on a 40 m floor was a few pixels across the picture: F framed everything.
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/walk.json", WalkJson());
  std::string floor;
  for (int k = 0; k <= 80; ++k) {
    for (int i = 0; i <= 80; ++i)
      floor += std::to_string(-17 + i * 0.5) + " 0 " + std::to_string(-19 + k * 0.5) + " 0 1 0\n";
  }
  test::WriteFile(dir + "/floor.pts", floor);
  // The distance in pixels between the feet at frame 1, (2, 0, 2) and (2, 0, 0), framed as
  // `how` says.
  auto feet_apart = [&](const std::vector<std::string>& how) {
    std::vector<std::string> args = {
        "--terrain",    dir + "/floor.pts", "--walk",       dir + "/walk.json", "--size", "640x400",
        "--screenshot", dir + "/shot.png",  "--dump-state", dir + "/state.json"};
    args.insert(args.end(), how.begin(), how.end());
    const RunResult r = View(args);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/state.json"));
    const json& tracks = state["walk"]["tracks"];
    CHECK(tracks[0]["visible"] == true);
    CHECK(tracks[1]["visible"] == true);
    const glm::vec2 l1(tracks[0]["pixel"][0].get<float>(), tracks[0]["pixel"][1].get<float>());
    const glm::vec2 r1(tracks[1]["pixel"][0].get<float>(), tracks[1]["pixel"][1].get<float>());
    return glm::length(l1 - r1);
  };
  const float all = feet_apart({}), walk = feet_apart({"--frame-walk"});
  INFO("feet " << all << " px apart framing everything, " << walk << " framing the walk");
  CHECK(walk > 4 * all);
  CHECK(walk < 400);  // the whole walk in the picture
  // A camera given wins; without a walk there is nothing to frame.
  CHECK(feet_apart({"--frame-walk", "--camera", "3 6 7 3 0 1"}) ==
        Approx(feet_apart({"--camera", "3 6 7 3 0 1"})));
  const RunResult none =
      View({"--terrain", dir + "/floor.pts", "--frame-walk", "--screenshot", dir + "/shot.png"});
  CHECK(none.exit_code == 2);
  CHECK_THAT(none.err, Catch::Contains("--frame-walk needs --walk"));
}

TEST_CASE("a walk without keys is pointed out", "[viewer][walk]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/empty.json",
                  R"({"format": "footfall-walk", "version": 1, "fps": 24, "tracks": []})");
  const RunResult r = View({"--walk", dir + "/empty.json", "--screenshot", dir + "/x.png"});
  CHECK(r.exit_code == 0);  // the overlay is still drawn
  CHECK_THAT(r.err, Catch::Contains("note: " + dir + "/empty.json has no keys: no walk to draw"));
  // Nor a range it does not have ("--frame 5 is outside the walk's 0-0").
  const RunResult framed =
      View({"--walk", dir + "/empty.json", "--frame", "5", "--screenshot", dir + "/y.png"});
  CHECK(framed.exit_code == 0);
  CHECK_THAT(framed.err, Catch::Contains("has no keys") && !Catch::Contains("outside the walk"));
}

TEST_CASE("bad inputs give a clear message and a non-zero exit", "[viewer][errors]") {
  const std::string dir = test::TempDir();
  const std::string shot = dir + "/x.png";
  SECTION("missing terrain file") {
    const RunResult r = View({"--terrain", dir + "/missing.pts", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains(dir + "/missing.pts") && Catch::Contains("cannot open"));
  }
  SECTION("malformed query strings") {
    RunResult r = View({"--terrain", kTerrain, "--query", "next 1 2 3", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--query \"next 1 2 3\": next: expected 6 numbers, found 3"));
    r = View({"--terrain", kTerrain, "--query", "jump 1 2 3", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("unknown command 'jump' (expected snap X Y Z, normal X Y Z "
                                      "or next X Y Z DX DY DZ)"));
    r = View({"--terrain", kTerrain, "--query", "snap 1 nan 3", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("argument 2 'nan' is not a finite number"));
    r = View({"--terrain", kTerrain, "--query", "next 1 2 3 0 0 0", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("direction DX DY DZ must be non-zero"));
  }
  SECTION("queries take footfall query's '#' comments; bad loading flags exit 2") {
    RunResult r = View({"--terrain", kTerrain, "--query", "snap 16 1 11 # the rock", "--screenshot",
                        dir + "/ok.png"});
    CHECK(r.exit_code == 0);
    r = View({"--terrain", kTerrain, "--query", "# only a comment", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--query \"# only a comment\": expected snap X Y Z"));
    for (const char* two : {"snap 1 1 1\nsnap 2 2 2", "snap 1 1\r1"}) {
      r = View({"--terrain", kTerrain, "--query", two, "--screenshot", shot});
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains("--query: expected one query per --query, on one line"));
    }
    r = View({"--terrain", kTerrain, "--separation", "nan", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    // --live-wait said "not in range 0.000000 to 1797..." (309 digits) or "Could not convert".
    for (const char* count : {"-1", "abc", "1.5", "2147483648"}) {
      r = View({"--terrain", kTerrain, "--live-wait", count, "--screenshot", shot});
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains("is not a whole number from 0 to 1000000"));
    }
    r = View({"--terrain", kTerrain, "--up-axis", "w", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    for (const char* up : {"w", "1,1,0", "0,0,0", "0,0,1,", "0,nan,1", "", "-"}) {
      r = View({"--terrain", kTerrain, "--up", up, "--screenshot", shot});
      INFO("--up " << up);
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains("--up \"" + std::string(up) +
                                        "\": expected an axis: x, y, "
                                        "z, -x, -y or -z, or a vector along one"));
    }
    // Loading flags without a terrain were ignored.
    for (const char* flag : {"--flat-normals", "--smooth-normals"}) {
      r = View({"--walk", dir + "/none.json", flag, "--screenshot", shot});
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains("is a loading flag of --terrain FILE, and no terrain"));
    }
    r = View({"--walk", dir + "/none.json", "--separation", "0.1", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--separation is a loading flag of --terrain FILE"));
    // Flags a point file has no use for exit 2 alike (a height map's frame exited 1).
    for (const std::vector<std::string>& flag : {std::vector<std::string>{"--separation", "0.1"},
                                                 {"--up-axis", "z"},
                                                 {"--cell-size", "2"},
                                                 {"--height-scale", "2"}}) {
      INFO(flag[0]);
      r = View({"--terrain", kTerrain, flag[0], flag[1], "--screenshot", shot});
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains(kTerrain + ": "));
    }
    // A point file is never resampled: resampling flags are refused for it, as by footfall.
    r = View({"--terrain", kTerrain, "--seed", "3", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--seed applies to meshes and height maps"));
  }
  SECTION("outputs never replace the inputs or each other") {
    // (A screenshot over the terrain file turned it into a PNG.)
    test::WriteFile(dir + "/t.pts", test::ReadFile(kTerrain));
    RunResult r = View({"--terrain", dir + "/t.pts", "--screenshot", dir + "/./t.pts"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("is the --terrain file; choose another output name"));
    CHECK(test::ReadFile(dir + "/t.pts") == test::ReadFile(kTerrain));
    r = View({"--terrain", dir + "/t.pts", "--screenshot", dir + "/s.png", "--dump-state",
              dir + "/s.png"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--screenshot and --dump-state name the same file"));
  }
  SECTION("height maps take every loading flag footfall's commands take") {
    // A 3 x 3 grid of 1 m cells; --cell-size 2 --height-scale 10 makes it 4 m across, 20 high
    // (resampled: the samples come within a separation of its edges).
    test::WriteFile(dir + "/g.asc",
                    "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
                    "0 1 2\n0 1 2\n0 1 2\n");
    const RunResult r = View({"--terrain", dir + "/g.asc", "--cell-size", "2", "--height-scale",
                              "10", "--crease-angle", "30", "--flat-normals", "--seed", "3",
                              "--screenshot", dir + "/ok.png", "--dump-state", dir + "/g.json"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const json state = json::parse(test::ReadFile(dir + "/g.json"));
    const auto lo = state["terrain"]["bounds_min"], hi = state["terrain"]["bounds_max"];
    CHECK(hi[0].get<double>() - lo[0].get<double>() == Approx(4).margin(0.5));
    CHECK(hi[1].get<double>() - lo[1].get<double>() == Approx(20).margin(2));
  }
  SECTION("points no camera can frame") {
    // (A point 1e300 away put the camera at NaN: a blank image and exit 0.)
    RunResult r = View({"--terrain", kTerrain, "--query", "snap 1e300 0 0", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("expected a point within +-1e15"));
    // A step the engine refuses (answered invalid_argument): its ideal point 1e200 away put the
    // camera at NaN, a blank image with exit 0.
    for (const char* step : {"next 0 0 0 1e200 0 0", "next 1 1 1 2e15 0 0"}) {
      INFO(step);
      r = View(
          {"--terrain", kTerrain, "--query", "snap 0 0 1", "--query", step, "--screenshot", shot});
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains("--query \"" + std::string(step) +
                                        "\": next: invalid query (a zero direction, one too "
                                        "long to square, or a foot or ideal point with a "
                                        "coordinate more than 1e15 from the terrain's centre)"));
    }
    test::WriteFile(dir + "/far.json",
                    "{\"format\": \"footfall-walk\", \"version\": 1, \"fps\": 24, \"tracks\": "
                    "[{\"name\": \"L\", \"kind\": \"foot\", \"keys\": [{\"frame\": 1, "
                    "\"phase\": \"end\", \"position\": [1e308, 0, 0], \"normal\": [0, 1, 0]}]}]}");
    r = View({"--walk", dir + "/far.json", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("tracks[0].keys[0].position: expected coordinates within "
                                      "+-1e15"));
  }
  SECTION("a screenshot named for another image format and a frame without a walk") {
    // (shot.jpg got PNG bytes and exit 0; --frame without --walk was ignored.)
    RunResult r = View({"--terrain", kTerrain, "--screenshot", dir + "/shot.jpg"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("shot.jpg: expected a .png file name"));
    CHECK_FALSE(std::ifstream(dir + "/shot.jpg").good());
    r = View({"--terrain", kTerrain, "--frame", "5", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--frame needs --walk FILE"));
    r = View({"--terrain", kTerrain, "--size", "64x40", "--screenshot", dir + "/Upper.PNG"});
    CHECK(r.exit_code == 0);
  }
  SECTION("screenshots that cannot be written") {
    // An empty path ran the interactive viewer (a hang under Xvfb); a full disk gave exit 0.
    RunResult r = View({"--terrain", kTerrain, "--screenshot", ""});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--screenshot: expected a PNG file path"));
    r = View({"--terrain", kTerrain, "--screenshot", "/dev/full"});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("/dev/full: cannot write PNG: No space left on device"));
    // A --dump-state that cannot be written failed after the screenshot had replaced the file
    // at its path: both are checked first, and the old screenshot stays.
    test::WriteFile(dir + "/old.png", "an earlier screenshot");
    r = View({"--terrain", kTerrain, "--screenshot", dir + "/old.png", "--dump-state",
              dir + "/missing/state.json"});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("--dump-state: cannot open '" + dir +
                                      "/missing/state.json' for writing"));
    CHECK(test::ReadFile(dir + "/old.png") == "an earlier screenshot");
    // ... and one that fails as it is written (a full disk): the screenshot had been replaced.
    r = View(
        {"--terrain", kTerrain, "--screenshot", dir + "/old.png", "--dump-state", "/dev/full"});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("/dev/full: cannot write the state dump"));
    CHECK(test::ReadFile(dir + "/old.png") == "an earlier screenshot");
    r = View({"--terrain", kTerrain, "--screenshot", dir + "/missing/shot.png"});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("--screenshot: cannot open '" + dir + "/missing/shot.png'"));
  }
  SECTION("unreachable server") {
    const RunResult r = View({"--server", "127.0.0.1:1", "--live", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("footfalld at 127.0.0.1:1"));
  }
  SECTION("missing and malformed walk files") {
    RunResult r = View({"--walk", dir + "/none.json", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains(dir + "/none.json: cannot open walk file"));
    test::WriteFile(
        dir + "/broken.json",
        "{\"format\": \"footfall-walk\", \"version\": 1, \"fps\": 24,\n \"tracks\": [\n");
    r = View({"--walk", dir + "/broken.json", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains(dir + "/broken.json:3:1: malformed JSON: syntax error"));
    test::WriteFile(dir + "/shape.json", R"({"format": "footfall-walk", "version": 1, "fps": 24,
        "tracks": [{"name": "L1", "kind": "foot", "keys": [
          {"frame": 1, "phase": "start", "position": [1, 2]}]}]})");
    r = View({"--walk", dir + "/shape.json", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains(dir + "/shape.json: tracks[0].keys[0].position: "
                                            "expected an array of 3 numbers"));
    test::WriteFile(dir + "/plain.json", R"({"fps": 24, "tracks": []})");
    r = View({"--walk", dir + "/plain.json", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains(dir + "/plain.json: format: expected \"footfall-walk\""));
    test::WriteFile(dir + "/descending.json", DescendingWalkJson());
    r = View({"--walk", dir + "/descending.json", "--screenshot", shot});
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains(dir + "/descending.json: tracks[0].keys[1].frame: "
                                            "frames must increase along a track"));
  }
  SECTION("bad sizes and missing content") {
    RunResult r = View({"--terrain", kTerrain, "--size", "12by4", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--size \"12by4\": expected WIDTHxHEIGHT"));
    r = View({"--terrain", kTerrain, "--size", "70000x20", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("in whole pixels from 1 to 65536"));
    // Each side digits alone: these were read as 64x48, 64x40 and 3x2.
    for (const char* size : {"64,48x", "x64 40", "3 2x", "64 x48", "1e2x50", "0x48"}) {
      r = View({"--terrain", kTerrain, "--size", size, "--screenshot", shot});
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains("--size \"" + std::string(size) + "\": expected"));
    }
    // Within that, the OpenGL's own limits, named. (Beyond GL_MAX_RENDERBUFFER_SIZE it was
    // "image size 20000x20 exceeds the GL limit of 16384", without the flag.)
    r = View({"--terrain", kTerrain, "--size", "20000x20", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("footfall-view: --size 20000x20: larger than this OpenGL "
                                      "draws, at most ") &&
                          Catch::Contains("(GL_MAX_RENDERBUFFER_SIZE ") &&
                          Catch::Contains(", GL_MAX_VIEWPORT_DIMS "));
    r = View({"--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("nothing to show"));
    // (--live-wait without --live was ignored: the screenshot was taken at once.)
    r = View({"--terrain", kTerrain, "--live-wait", "2", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--live-wait needs --live"));
    r = View({"--terrain", kTerrain, "--frame", "nan", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--frame: 'nan' is not a finite number"));
    r = View({"--terrain", kTerrain, "--tolerance", "nan", "--screenshot", shot});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--tolerance: 'nan' is not a finite number >= 0"));
  }
  SECTION("no display") {
    const RunResult r =
        Run({kView, "--terrain", kTerrain, "--screenshot", shot}, {"DISPLAY="}, kTimeout);
    CHECK(r.exit_code == 1);
    CHECK_THAT(r.err, Catch::Contains("cannot open a display"));
  }
  SECTION("--version and --help that cannot be written") {
    // They exited 0 with nothing written.
    for (const char* flag : {"--version", "--help"}) {
      const RunResult r =
          Run({"/bin/sh", "-c", std::string(kView) + " " + flag + " > /dev/full"}, {}, kTimeout);
      CHECK(r.exit_code == 1);
      CHECK_THAT(r.err, Catch::Contains("footfall-view: cannot write standard output"));
    }
  }
  std::ifstream none(shot);
  CHECK_FALSE(none.good());  // no failed run leaves a screenshot
}

TEST_CASE("a screenshot larger than the memory allows says so", "[viewer][errors]") {
  // 16384 x 16384 is within the GL limits but takes some 4 GB of memory; under a 1.5 GB
  // address space it ended in "offscreen framebuffer incomplete (status 36054)" or
  // "std::bad_alloc".
  const std::string dir = test::TempDir();
  const RunResult r =
      Run({"/bin/sh", "-c", "ulimit -v 1500000 && exec \"$0\" \"$@\"", kView, "--terrain", kTerrain,
           "--size", "16384x16384", "--screenshot", dir + "/big.png"},
          {test::XDisplay()}, kTimeout);
  INFO(r.err);
  REQUIRE_FALSE(r.timed_out);
  CHECK(r.exit_code == 1);
  CHECK_THAT(r.err, Catch::StartsWith("footfall-view: --size 16384x16384: ") &&
                        Catch::Contains("; try a smaller --size"));
  std::ifstream none(dir + "/big.png");
  CHECK_FALSE(none.good());
}

TEST_CASE("comma-separated --query numbers are drawn like spaced ones", "[viewer][query]") {
  const std::string dir = test::TempDir();
  const RunResult r =
      View({"--terrain", kTerrain, "--query", "next 10,1,10 1.2,0,0.3", "--size", "160x100",
            "--screenshot", dir + "/shot.png", "--dump-state", dir + "/state.json"});
  REQUIRE(r.exit_code == 0);
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  REQUIRE(state["queries"].size() == 1);
  CHECK(state["queries"][0]["query"] == "next 10 1 10 1.2 0 0.3");
  CHECK(state["queries"][0]["op"] == "next");
  CHECK(state["queries"][0]["candidates"].get<int>() > 0);
}

TEST_CASE("walk poses follow keys and swing arcs", "[viewer][walk]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/walk.json", WalkJson());
  Walk walk;
  std::string error;
  REQUIRE(ReadWalkJson(dir + "/walk.json", &walk, &error) == Status::kOk);
  REQUIRE(walk.tracks.size() == 3);
  CHECK(walk.tracks[2].kind == TrackKind::kBody);
  CHECK(walk.tracks[2].rotations[1].w == 2);  // the reader keeps rotations as written
  const WalkTrack& l1 = walk.tracks[0];
  SECTION("keys are hit exactly and the foot holds outside its keys") {
    CHECK(viewer::PoseAt(l1, 1).position == Vec3{2, 0, 2});
    CHECK(viewer::PoseAt(l1, 7).position.y == Approx(0.5));
    CHECK(viewer::PoseAt(l1, 13).position == Vec3{4, 0, 2});
    CHECK(viewer::PoseAt(l1, 0).position == Vec3{2, 0, 2});
    CHECK(viewer::PoseAt(l1, 99).position == Vec3{4, 0, 2});
  }
  SECTION("the swing is a smooth arc, above the straight line and swinging") {
    const viewer::TrackPose p = viewer::PoseAt(l1, 4);
    CHECK(p.swinging);
    CHECK(p.position.y > 0.3);
    CHECK(p.position.y < 0.5);
    CHECK(p.position.x == Approx(2.5));
  }
  SECTION("the body interpolates linearly") {
    CHECK(viewer::PoseAt(walk.tracks[2], 13).position.x == Approx(3));
  }
  SECTION("foot normals are drawn at unit length at their keys too") {
    // (A file's [0, 40, 0] was used as written at a key and outside the keys: a normal drawn
    // 40 times as long, off the picture.)
    WalkTrack long_normals = l1;
    for (WalkKey& k : long_normals.keys) k.normal = k.normal * 40.0;
    for (const double frame : {0.0, 1.0, 4.0, 7.0, 13.0, 99.0}) {
      INFO("frame " << frame);
      const Vec3 n = viewer::PoseAt(long_normals, frame).normal;
      CHECK(Length(n) == Approx(1));
      CHECK(Distance(n, viewer::PoseAt(l1, frame).normal) < 1e-12);
    }
  }
  SECTION("a foot lifting on the frame it lands swings from its end key") {
    // A gait of one group: end, mid, end, mid, end.
    WalkTrack hop;
    hop.kind = TrackKind::kFoot;
    const KeyPhase phases[5] = {KeyPhase::kEnd, KeyPhase::kMid, KeyPhase::kEnd, KeyPhase::kMid,
                                KeyPhase::kEnd};
    for (int k = 0; k < 5; ++k) {
      WalkKey key;
      key.frame = 1 + 3 * k, key.phase = phases[k];
      key.position = {k * 0.5, k % 2 ? 0.5 : 0.0, 0};
      hop.keys.push_back(key);
    }
    for (double frame : {2.5, 8.5}) {  // halfway up the first and the second swing
      const viewer::TrackPose p = viewer::PoseAt(hop, frame);
      CHECK(p.swinging);
      CHECK(p.position.y > 0.25);  // on the arc, above the straight line's 0.25
    }
  }
  double first = 0, last = 0;
  viewer::FrameRange(walk, &first, &last);
  CHECK(first == 1);
  CHECK(last == 25);
}

TEST_CASE("a walk far from frame 0 is shown at its own frames with whole numbers",
          "[viewer][walk]") {
  // `footfall generate --start-frame 1e9` keys frames past 1e9, which --frame refused, and the
  // overlay wrote frames in six digits: "frame 1e+09 of 1e+09-1e+09".
  const std::string dir = test::TempDir();
  std::string walk = WalkJson();
  for (const char* frame : {"1", "7", "13", "19", "25"}) {
    const std::string from = std::string("\"frame\": ") + frame + ",";
    const std::string to =
        "\"frame\": 10000000" + std::string(std::strlen(frame) == 1 ? "0" : "") + frame + ",";
    for (size_t at = walk.find(from); at != std::string::npos; at = walk.find(from, at))
      walk.replace(at, from.size(), to), at += to.size();
  }
  test::WriteFile(dir + "/walk.json", walk);
  const RunResult r =
      View({"--walk", dir + "/walk.json", "--frame", "1000000010.5", "--size", "640x360",
            "--screenshot", dir + "/shot.png", "--dump-state", dir + "/state.json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json state = json::parse(test::ReadFile(dir + "/state.json"));
  CHECK(state["walk"]["first_frame"] == 1000000001);
  CHECK(state["walk"]["last_frame"] == 1000000025);
  CHECK(state["walk"]["frame"] == 1000000010.5);
  bool shown = false;
  for (const json& line : state["hud"]) {
    const std::string text = line["text"];
    shown |= text.find("frame 1000000010.5 of 1000000001 to 1000000025 at 24 fps") == 0;
  }
  CHECK(shown);
  // A frame outside the walk is noted in the walk's own numbers.
  const RunResult outside = View({"--walk", dir + "/walk.json", "--frame", "-3e9", "--size",
                                  "64x64", "--screenshot", dir + "/shot.png"});
  CHECK(outside.exit_code == 0);
  CHECK_THAT(outside.err, Catch::Contains("--frame -3000000000 is outside the walk's "
                                          "1000000001 to 1000000025; showing 1000000001"));
  // A fractional frame just outside is quoted as given, not rounded into the range.
  const RunResult just_outside = View({"--walk", dir + "/walk.json", "--frame", "1000000000.9999",
                                       "--size", "64x64", "--screenshot", dir + "/shot.png"});
  CHECK(just_outside.exit_code == 0);
  CHECK_THAT(just_outside.err, Catch::Contains("--frame 1000000000.9999 is outside the walk's "
                                               "1000000001 to 1000000025; showing 1000000001"));
  CHECK(viewer::ExactFrameText(0.0001) == "0.0001");
  CHECK(viewer::ExactFrameText(12.25) == "12.25");
  CHECK(viewer::ExactFrameText(-3e9) == "-3000000000");
  CHECK(viewer::ExactFrameText(1e-300) == "1e-300");
  CHECK(viewer::ExactFrameText(1e300) == "1e+300");
  CHECK(viewer::FrameText(12.25) == "12.25");
  CHECK(viewer::FrameText(1e6) == "1000000");
  CHECK(viewer::FrameText(2.0 / 3) == "0.667");
  CHECK(viewer::FrameText(-0.0001) == "0");
  CHECK(viewer::FrameText(1e300) == "1e+300");
  // From 1e15 on, always with an exponent (1e15 + 1 was written in digits beside "1e+15").
  CHECK(viewer::FrameText(1e15) == "1e+15");
  CHECK(viewer::FrameText(1e15 + 1) == "1.000000000000001e+15");
  CHECK(viewer::FrameText(-999999999999999.5) == "-999999999999999.5");
}

TEST_CASE("walk files with descending frames are refused", "[viewer][walk]") {
  const std::string dir = test::TempDir();
  test::WriteFile(dir + "/w.json", DescendingWalkJson());
  Walk walk;
  std::string error;
  CHECK(ReadWalkJson(dir + "/w.json", &walk, &error) == Status::kParseError);
  CHECK(error ==
        dir + "/w.json: tracks[0].keys[1].frame: frames must increase along a track (line 4)");
}

}  // namespace
}  // namespace footfall
