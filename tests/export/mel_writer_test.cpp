// The MEL writer: the script, parsed back, creates the expected locators and groups and keys
// each attribute once per distinct frame with the walk's values.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/export/euler.h"
#include "footfall/export/mel_writer.h"
#include "footfall/steps/linear_units.h"
#include "walk_fixtures.h"

using namespace footfall;

namespace {

struct MelKey {
  double frame;
  double value;
};

// What a MEL walk script does, recovered line by line.
struct MelScript {
  std::string time_unit;
  std::string root;  // the root group's createNode name
  double min_time = NAN, max_time = NAN;
  std::vector<std::string> groups;                // createNode transform -parent names, in order
  std::vector<std::string> locators;              // spaceLocator -n names, in order
  std::map<std::string, std::string> parent_of;   // locator -> "$footfall_root" or group
  std::map<std::string, std::string> track_attr;  // locator -> footfallTrack value
  std::map<std::string, int> rotate_order;        // locator -> rotateOrder set (bodies)
  std::map<std::string, std::map<std::string, std::vector<MelKey>>> keys;  // loc -> attr
  std::vector<std::string> warnings;
  int braces = 0;
  std::string angle_unit;                // set by the script, before any rotation key
  bool angle_restored = false;           // the user's angle unit put back, after every key
  std::string linear_unit;               // set by the script (Walk::unit), before any key
  bool linear_restored = false;          // the user's linear unit put back, after every key
  bool translate_before_linear = false;  // a translate key before the linear unit was set
};

// Every setKeyframe line must match `key`: keys carry linear tangents, as glTF's LINEAR samplers,
// and numbers have no exponent.
MelScript ParseMel(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  static const std::regex unit(R"re(^currentUnit -time "([^"]+)";$)re");
  static const std::regex playback(R"re(^playbackOptions -minTime (\S+) -maxTime (\S+) .*;$)re");
  static const std::regex root(
      R"re(^string \$footfall_root = `createNode transform -name "(\w+)"`;$)re");
  static const std::regex group(
      R"re(^\$footfall_groups\[(\d+)\] = `createNode transform -name "(\w+)" -parent \$footfall_root`;$)re");
  static const std::regex locator(R"re(^\$footfall_node = `spaceLocator -n "(\w+)"`;$)re");
  static const std::regex parent(
      R"re(^\$footfall_node = `parent \$footfall_node\[0\] (\$footfall_root|\$footfall_groups\[(\d+)\])`;$)re");
  static const std::regex track(
      R"re(^setAttr -type "string" \(\$footfall_node\[0\] \+ ".footfallTrack"\) "(.*)";$)re");
  static const std::regex rotate_order(
      R"re(^setAttr \(\$footfall_node\[0\] \+ "\.rotateOrder"\) (\d);$)re");
  static const std::regex key(
      R"re(^setKeyframe -t (-?[0-9.]+) -at (translate[XYZ]|rotate[XYZ]) -v (-?[0-9.]+) -itt linear -ott linear \$footfall_node\[0\];$)re");
  static const std::regex angle_query(
      R"re(^string \$footfall_angle_unit = `currentUnit -query -angle`;$)re");
  static const std::regex linear_query(
      R"re(^string \$footfall_linear_unit = `currentUnit -query -linear`;$)re");
  static const std::regex linear_set(R"re(^currentUnit -linear "(\w+)";$)re");
  MelScript script;
  bool angle_queried = false, linear_queried = false;
  std::string line, current;
  std::smatch m;
  while (std::getline(in, line)) {
    if (line == "{") ++script.braces;
    if (line == "}") --script.braces;
    if (std::regex_match(line, m, angle_query)) {
      angle_queried = true;
    } else if (line == "currentUnit -angle \"deg\";") {
      REQUIRE(angle_queried);
      script.angle_unit = "deg";
    } else if (line == "currentUnit -angle $footfall_angle_unit;") {
      REQUIRE(script.angle_unit == "deg");
      script.angle_restored = true;
    } else if (std::regex_match(line, m, linear_query)) {
      linear_queried = true;
    } else if (std::regex_match(line, m, linear_set)) {
      REQUIRE(linear_queried);
      REQUIRE(script.keys.empty());
      script.linear_unit = m[1];
    } else if (line == "currentUnit -linear $footfall_linear_unit;") {
      REQUIRE(!script.linear_unit.empty());
      script.linear_restored = true;
    } else if (line.rfind("currentUnit -linear", 0) == 0) {
      FAIL("unexpected currentUnit line: " << line);
    } else if (std::regex_match(line, m, unit)) {
      script.time_unit = m[1];
    } else if (std::regex_match(line, m, playback)) {
      script.min_time = std::stod(m[1]);
      script.max_time = std::stod(m[2]);
    } else if (std::regex_match(line, m, root)) {
      script.root = m[1];
    } else if (std::regex_match(line, m, group)) {
      REQUIRE(std::stoul(m[1]) == script.groups.size());
      script.groups.push_back(m[2]);
    } else if (std::regex_match(line, m, locator)) {
      current = m[1];
      script.locators.push_back(current);
    } else if (std::regex_match(line, m, parent)) {
      REQUIRE(!current.empty());
      script.parent_of[current] = m[2].matched ? script.groups.at(std::stoul(m[2])) : m[1].str();
    } else if (std::regex_match(line, m, track)) {
      script.track_attr[current] = m[1];
    } else if (std::regex_match(line, m, rotate_order)) {
      REQUIRE(!current.empty());
      REQUIRE(script.keys.count(current) == 0);  // set before any key
      script.rotate_order[current] = std::stoi(m[1]);
    } else if (std::regex_match(line, m, key)) {
      REQUIRE(!current.empty());
      REQUIRE(!script.angle_restored);
      REQUIRE(!script.linear_restored);
      if (m[2].str().rfind("rotate", 0) == 0) REQUIRE(script.angle_unit == "deg");
      if (m[2].str().rfind("translate", 0) == 0 && script.linear_unit.empty())
        script.translate_before_linear = true;
      script.keys[current][m[2]].push_back({std::stod(m[1]), std::stod(m[3])});
    } else if (line.rfind("warning ", 0) == 0) {
      script.warnings.push_back(line);
    } else if (line.rfind("setKeyframe", 0) == 0) {
      FAIL("unexpected setKeyframe line: " << line);
    }
  }
  return script;
}

// The whole text of the file at `path`.
std::string FileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in.good());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string WriteAndKeep(const Walk& walk, const std::string& name) {
  const std::string path = test::ScratchPath(name);
  std::string error;
  REQUIRE(WriteMel(walk, path, &error) == Status::kOk);
  return path;
}

// The rotation matrix R = Ry * Rx * Rz of Euler degrees in Maya's ZXY rotate order (Z first,
// then X, then Y) applied to `v`.
Vec3 RotateEulerZxy(const Vec3& euler_deg, const Vec3& v) {
  const double k = 3.14159265358979323846 / 180;
  const double cx = std::cos(euler_deg.x * k), sx = std::sin(euler_deg.x * k);
  const double cy = std::cos(euler_deg.y * k), sy = std::sin(euler_deg.y * k);
  const double cz = std::cos(euler_deg.z * k), sz = std::sin(euler_deg.z * k);
  Vec3 a{cz * v.x - sz * v.y, sz * v.x + cz * v.y, v.z};
  Vec3 b{a.x, cx * a.y - sx * a.z, sx * a.y + cx * a.z};
  return {cy * b.x + sy * b.z, b.y, -sy * b.x + cy * b.z};
}

// A locator's Euler keys (rotateX/Y/Z) in key order.
std::vector<Vec3> LocatorEuler(const MelScript& script, const std::string& locator) {
  const auto& keys = script.keys.at(locator);
  std::vector<Vec3> euler;
  for (size_t i = 0; i < keys.at("rotateX").size(); ++i) {
    euler.push_back(
        {keys.at("rotateX")[i].value, keys.at("rotateY")[i].value, keys.at("rotateZ")[i].value});
  }
  return euler;
}

// Checks that every key's Euler angles, applied in ZXY order, turn the axes as `rotations` do.
void CheckReproduces(const std::vector<Vec3>& euler, const std::vector<Quat>& rotations) {
  REQUIRE(euler.size() == rotations.size());
  for (size_t i = 0; i < euler.size(); ++i) {
    for (const Vec3& axis : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}}) {
      const Vec3 got = RotateEulerZxy(euler[i], axis);
      const Vec3 want = test::Rotated(rotations[i], axis);
      INFO("key " << i << " axis " << axis.x << axis.y << axis.z);
      CHECK(got.x == Approx(want.x).margin(1e-9));
      CHECK(got.y == Approx(want.y).margin(1e-9));
      CHECK(got.z == Approx(want.z).margin(1e-9));
    }
  }
}

}  // namespace

TEST_CASE("WriteMel keys a locator per track", "[export][mel]") {
  const Walk walk = test::BipedWalk();
  const std::string path = WriteAndKeep(walk, "biped.mel");
  const MelScript script = ParseMel(path);
  CHECK(script.braces == 0);
  CHECK(script.time_unit == "film");
  // Rotations keyed in degrees whatever the scene's angle unit, which is put back after.
  CHECK(script.angle_unit == "deg");
  CHECK(script.angle_restored);
  CHECK(script.root == "footfall_walk");
  CHECK(script.min_time == 1);
  CHECK(script.max_time == 37);
  CHECK(script.groups.empty());
  REQUIRE(script.locators == std::vector<std::string>{"L", "R", "body"});
  for (const std::string& name : script.locators) {
    CHECK(script.parent_of.at(name) == "$footfall_root");
    CHECK(script.track_attr.at(name) == name);
  }

  SECTION("feet: translate keys only, one per distinct frame, with the key values") {
    const auto& left = script.keys.at("L");
    CHECK(left.size() == 3);
    const auto& right = script.keys.at("R");
    CHECK(right.size() == 3);
    const char* axes[] = {"translateX", "translateY", "translateZ"};
    for (int axis = 0; axis < 3; ++axis) {
      REQUIRE(left.at(axes[axis]).size() == 6);
      REQUIRE(right.at(axes[axis]).size() == 5);  // frame 25 keyed once
      for (size_t i = 0; i < 6; ++i) {
        const WalkKey& key = walk.tracks[0].keys[i];
        const double expected[] = {key.position.x, key.position.y, key.position.z};
        CHECK(left.at(axes[axis])[i].frame == key.frame);
        CHECK(left.at(axes[axis])[i].value == expected[axis]);
      }
    }
    // The later of the two frame-25 keys is the one kept.
    CHECK(right.at("translateY")[2].frame == 25);
    CHECK(right.at("translateY")[2].value == Approx(0.01));
  }
  SECTION("body: translate and rotate keys; Euler angles reproduce the quaternions") {
    CHECK(script.rotate_order.at("body") == 2);  // zxy
    CHECK(script.rotate_order.count("L") == 0);
    const auto& body = script.keys.at("body");
    REQUIRE(body.size() == 6);
    for (const auto& entry : body) CHECK(entry.second.size() == 5);
    const std::vector<Vec3> eulers = LocatorEuler(script, "body");
    CheckReproduces(eulers, {walk.tracks[2].rotations.begin(), walk.tracks[2].rotations.end()});
    const double yaw[] = {0, 60, 150, 170, 190};
    for (size_t i = 0; i < 5; ++i) {
      const Vec3 euler = eulers[i];
      // Rotating the forward axis by the Euler angles matches yawing it.
      const Vec3 forward = RotateEulerZxy(euler, {0, 0, 1});
      const double k = 3.14159265358979323846 / 180;
      CHECK(forward.x == Approx(std::sin(yaw[i] * k)).margin(1e-5));
      CHECK(forward.z == Approx(std::cos(yaw[i] * k)).margin(1e-5));
      CHECK(body.at("translateY")[i].value == Approx(walk.tracks[2].keys[i].position.y));
    }
    // Unwrapped: no key turns more than 180 degrees from the previous one.
    for (size_t i = 1; i < 5; ++i) {
      CHECK(std::abs(body.at("rotateY")[i].value - body.at("rotateY")[i - 1].value) < 180);
    }
  }
  std::remove(path.c_str());
}

TEST_CASE("WriteMel keys lengths in the walk's unit when it has one", "[export][mel]") {
  // Maya reads setKeyframe values in the scene's linear unit (centimetres by default): a walk in
  // metres was keyed 100 times small. With a unit, it is set while keying and the user's put
  // back, as for angles; the keys are the same numbers.
  Walk walk = test::BipedWalk();
  const std::string plain_path = WriteAndKeep(walk, "scene_unit.mel");
  const MelScript plain = ParseMel(plain_path);
  CHECK(plain.linear_unit.empty());
  CHECK_FALSE(plain.linear_restored);
  CHECK(FileText(plain_path).find("// Lengths are keyed in the scene's linear unit") !=
        std::string::npos);
  for (const std::string unit : {"m", "cm", "mm", "km", "in", "ft", "yd", "mi"}) {
    INFO(unit);
    CHECK(MetresPerLinearUnit(unit) > 0);
    walk.unit = unit;
    const std::string path = test::ScratchPath("unit_" + unit + ".mel");
    std::string error;
    REQUIRE(WriteMel(walk, path, &error) == Status::kOk);
    const MelScript named = ParseMel(path);
    CHECK(named.linear_unit == unit);
    CHECK(named.linear_restored);
    CHECK_FALSE(named.translate_before_linear);
    CHECK(named.braces == 0);
    CHECK(named.keys.size() == plain.keys.size());
    for (const auto& [locator, attrs] : plain.keys) {
      for (const auto& [attr, keys] : attrs) {
        const auto& other = named.keys.at(locator).at(attr);
        REQUIRE(other.size() == keys.size());
        for (size_t i = 0; i < keys.size(); ++i) {
          CHECK(other[i].frame == keys[i].frame);
          CHECK(other[i].value == keys[i].value);
        }
      }
    }
    CHECK(FileText(path).find("// Lengths are in " + unit + " and keyed so") != std::string::npos);
    std::remove(path.c_str());
  }
  for (const std::string bad : {"furlong", "M", "meter", " m", "m\"; quit -f; \""}) {
    INFO(bad);
    CHECK(MetresPerLinearUnit(bad) == 0);
    walk.unit = bad;
    const std::string path = test::ScratchPath("unit_bad.mel");
    std::string error;
    CHECK(WriteMel(walk, path, &error) == Status::kInvalidArgument);
    CHECK(error.rfind("the walk's unit '", 0) == 0);
    CHECK(error.find("is none of Maya's linear units (mm, cm, m, km, in, ft, yd or mi)") !=
          std::string::npos);
    CHECK_FALSE(std::ifstream(path).good());
  }
  std::remove(plain_path.c_str());
}

TEST_CASE("WriteMel writes frames and values that read back exactly, without exponents",
          "[export][mel]") {
  // Fixed 6 decimals turned frame 1.0000004 into 1 and lost a small-scale world's positions.
  Walk walk = test::BipedWalk();
  WalkTrack& left = walk.tracks[0];
  left.keys[0].frame = 1.0000004;
  left.keys[0].position = {1e-9, 123456.789012345, -2.5e-5};
  left.keys[1].position = {1e15, 0.1 + 0.2, -0.0};
  left.keys[2].position = {-1.7976931348623157e308, 1e-300, 2.0 / 3.0};
  left.keys[3].frame = 24.999999999999996;
  walk.tracks[2].keys[0].frame = 1.0000004;
  walk.tracks[2].keys[0].position = {-1e-12, 1e22, 1234.5};
  walk.tracks[2].keys[1].position = {-2147483648.0, 2147483647.0, 0.5};
  const std::string path = WriteAndKeep(walk, "precision.mel");
  const MelScript script = ParseMel(path);  // fails on any key line with an exponent
  CHECK(script.min_time == 1.0000004);
  const char* axes[] = {"translateX", "translateY", "translateZ"};
  for (size_t t : {size_t{0}, size_t{2}}) {
    const auto& keys = script.keys.at(script.locators[t]);
    for (int axis = 0; axis < 3; ++axis) {
      REQUIRE(keys.at(axes[axis]).size() == walk.tracks[t].keys.size());
      for (size_t i = 0; i < walk.tracks[t].keys.size(); ++i) {
        const WalkKey& key = walk.tracks[t].keys[i];
        const double expected[] = {key.position.x, key.position.y, key.position.z};
        INFO("track " << t << " key " << i << " axis " << axis);
        CHECK(keys.at(axes[axis])[i].frame == key.frame);
        CHECK(keys.at(axes[axis])[i].value == expected[axis]);
      }
    }
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  // Shortest form: no digits beyond those needed, "-0" written as 0, no trailing zeros.
  CHECK_THAT(text.str(),
             Catch::Contains("setKeyframe -t 1.0000004 -at translateX -v 0.000000001 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateY -v 123456.789012345 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateZ -v -0.000025 "));
  // Whole numbers beyond a 32-bit int keep a point: MEL would read them as an int.
  CHECK_THAT(text.str(), Catch::Contains("-at translateX -v 1000000000000000.0 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateY -v 0.30000000000000004 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateZ -v 0 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateY -v 10000000000000000000000.0 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateX -v -2147483648.0 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateY -v 2147483647 "));
  CHECK_THAT(text.str(), Catch::Contains("-at translateZ -v 1234.5 "));
  std::remove(path.c_str());
}

TEST_CASE("WriteMel keys bodies in rotate order ZXY, smooth at every heading", "[export][mel]") {
  const double k = 3.14159265358979323846 / 180;
  const auto axis_angle = [k](const Vec3& axis, double degrees) {
    const double half = degrees * k / 2;
    return Quat{axis.x * std::sin(half), axis.y * std::sin(half), axis.z * std::sin(half),
                std::cos(half)};
  };
  const auto multiply = [](const Quat& a, const Quat& b) {
    return Quat{a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
                a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
  };
  Walk walk;
  walk.fps = 24;
  // A body on a slope (tilted 4 degrees about X and 3 about Z) turning 2 degrees a key through
  // heading +X (yaw 90, gimbal lock in XYZ) and on through 180 and -X (yaw 270).
  WalkTrack turning;
  turning.name = "turning";
  turning.kind = TrackKind::kBody;
  const Quat tilt = multiply(axis_angle({1, 0, 0}, 4), axis_angle({0, 0, 1}, 3));
  for (int i = 0; i <= 110; ++i) {
    WalkKey key;
    key.frame = 1 + i;
    turning.keys.push_back(key);
    turning.rotations.push_back(multiply(tilt, axis_angle({0, 1, 0}, 60 + 2 * i)));
  }
  // Any rotations at all, not unit length.
  WalkTrack tumbling;
  tumbling.name = "tumbling";
  tumbling.kind = TrackKind::kBody;
  std::mt19937 rng(17);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 200; ++i) {
    WalkKey key;
    key.frame = 1 + i;
    tumbling.keys.push_back(key);
    tumbling.rotations.push_back({normal(rng), normal(rng), normal(rng), normal(rng)});
  }
  walk.tracks = {turning, tumbling};
  const std::string path = WriteAndKeep(walk, "zxy.mel");
  const MelScript script = ParseMel(path);
  CHECK(script.rotate_order.at("turning") == 2);
  CHECK(script.rotate_order.at("tumbling") == 2);
  const std::vector<Vec3> turning_euler = LocatorEuler(script, "turning");
  CheckReproduces(turning_euler, {turning.rotations.begin(), turning.rotations.end()});
  CheckReproduces(LocatorEuler(script, "tumbling"),
                  {tumbling.rotations.begin(), tumbling.rotations.end()});
  // A 2 degree turn moves no channel by more than a few degrees (XYZ swung them by ~80).
  for (size_t i = 1; i < turning_euler.size(); ++i) {
    INFO("key " << i);
    CHECK(std::abs(turning_euler[i].x - turning_euler[i - 1].x) < 3);
    CHECK(std::abs(turning_euler[i].y - turning_euler[i - 1].y) < 3);
    CHECK(std::abs(turning_euler[i].z - turning_euler[i - 1].z) < 3);
  }
  std::remove(path.c_str());
}

TEST_CASE("WriteMel groups crowd characters and sanitises names", "[export][mel]") {
  Walk walk = test::CrowdWalk();
  walk.tracks[0].name = "3rd leg|x";
  const std::string path = WriteAndKeep(walk, "crowd.mel");
  const MelScript script = ParseMel(path);
  CHECK(script.time_unit == "ntsc");
  CHECK(script.groups == std::vector<std::string>{"ant_1", "ant_2"});
  CHECK(script.locators == std::vector<std::string>{"ant_1_3rd_leg_x", "ant_1_R1", "ant_1_body",
                                                    "ant_2_L1", "ant_2_R1", "ant_2_body"});
  CHECK(script.parent_of.at("ant_1_body") == "ant_1");
  CHECK(script.parent_of.at("ant_2_L1") == "ant_2");
  CHECK(script.track_attr.at("ant_1_3rd_leg_x") == "ant 1/3rd leg|x");
  for (const std::string& name : script.locators) {
    CHECK(script.keys.at(name).at("translateX").size() == 3);
  }
  CHECK(script.keys.at("ant_2_body").at("rotateY").size() == 3);
  CHECK(script.rotate_order.at("ant_1_body") == 2);
  CHECK(script.rotate_order.at("ant_2_body") == 2);
  CHECK(script.rotate_order.count("ant_2_L1") == 0);
  CHECK(script.keys.at("ant_2_L1").count("rotateY") == 0);
  CHECK(script.keys.at("ant_2_L1").at("translateX")[2].value == Approx(1.9));
  std::remove(path.c_str());
}

TEST_CASE("WriteMel writes a script of many megabytes whole", "[export][mel]") {
  // The script is written as it is built, a megabyte at a time: 60,000 keys (some 14 MB) cross
  // many of those pieces, and every key reads back.
  const Walk walk = test::LongCrowdWalk(10000);
  const std::string path = WriteAndKeep(walk, "many_keys.mel");
  const MelScript script = ParseMel(path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  CHECK(in.tellg() > std::streamoff{10} << 20);
  CHECK(script.braces == 0);
  REQUIRE(script.locators.size() == 6);
  for (size_t t = 0; t < script.locators.size(); ++t) {
    const auto& x = script.keys.at(script.locators[t]).at("translateX");
    REQUIRE(x.size() == 10003);
    CHECK(x.back().frame == walk.tracks[t].keys.back().frame);
    CHECK(x.back().value == Approx(x[2].value + 1.0 / 3.0 + 10));
  }
  CHECK(script.keys.at("ant_2_body").at("rotateY").size() == 10003);
  std::remove(path.c_str());
}

TEST_CASE("WriteMel gives no group or locator the root group's name", "[export][mel]") {
  // A foot named footfall_walk got the root's name, and Maya renamed one of the two.
  SECTION("feet") {
    Walk walk = test::BipedWalk();
    walk.tracks[0].name = "footfall_walk";
    walk.tracks[1].name = "footfall_walk_2";
    const std::string path = WriteAndKeep(walk, "root_name.mel");
    const MelScript script = ParseMel(path);
    CHECK(script.root == "footfall_walk");
    CHECK(script.locators ==
          std::vector<std::string>{"footfall_walk_3", "footfall_walk_2", "body"});
    CHECK(script.track_attr.at("footfall_walk_3") == "footfall_walk");
    std::remove(path.c_str());
  }
  SECTION("crowd characters") {
    Walk walk = test::CrowdWalk();
    for (WalkTrack& track : walk.tracks) {
      if (track.character == "ant 1") track.character = "footfall walk";
    }
    const std::string path = WriteAndKeep(walk, "root_name_crowd.mel");
    const MelScript script = ParseMel(path);
    CHECK(script.root == "footfall_walk");
    CHECK(script.groups == std::vector<std::string>{"footfall_walk_2", "ant_2"});
    CHECK(script.parent_of.at("footfall_walk_L1") == "footfall_walk_2");
    std::remove(path.c_str());
  }
}

TEST_CASE("WriteMel lets names legal as given keep them before sanitised ones", "[export][mel]") {
  // (A foot 'left foot', sanitised to left_foot, took the name of the foot named left_foot.)
  Walk walk = test::BipedWalk();
  walk.tracks[0].name = "left foot";
  walk.tracks[1].name = "left_foot";
  const std::string path = WriteAndKeep(walk, "claims.mel");
  const MelScript script = ParseMel(path);
  CHECK(script.locators == std::vector<std::string>{"left_foot_2", "left_foot", "body"});
  CHECK(script.track_attr.at("left_foot") == "left_foot");
  CHECK(script.track_attr.at("left_foot_2") == "left foot");
  std::remove(path.c_str());
}

TEST_CASE("WriteMel names without a Maya time unit and special characters", "[export][mel]") {
  Walk walk = test::BipedWalk();
  walk.fps = 23;
  walk.tracks[0].name = "9";
  walk.tracks[1].name = "a\"b\nc";
  walk.stopped = "cliff at step 3\nposition (1, 2, 3)";
  const std::string path = WriteAndKeep(walk, "odd.mel");
  const MelScript script = ParseMel(path);
  CHECK(script.time_unit.empty());
  REQUIRE(script.warnings.size() == 1);
  CHECK_THAT(script.warnings[0], Catch::Contains("no time unit for 23 fps"));
  CHECK(script.locators == std::vector<std::string>{"_9", "a_b_c", "body"});
  CHECK(script.track_attr.at("a_b_c") == "a\\\"b\\nc");  // escaped in the MEL string
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  CHECK_THAT(text.str(), Catch::Contains("// The walk stopped early: cliff at step 3 position"));
  std::remove(path.c_str());
}

TEST_CASE("WriteMel writes names that are not UTF-8 with U+FFFD", "[export][mel]") {
  Walk walk = test::BipedWalk();
  walk.tracks[0].name = "f\xc3\xbc\xff";  // a valid two-byte sequence, then a stray byte
  walk.stopped = "cut \xe2\x82";
  const std::string path = WriteAndKeep(walk, "utf8.mel");
  const MelScript script = ParseMel(path);
  CHECK(script.track_attr.at("f___") == "f\xc3\xbc\xEF\xBF\xBD");
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  CHECK_THAT(text.str(),
             Catch::Contains("// The walk stopped early: cut \xEF\xBF\xBD\xEF\xBF\xBD\n"));
  CHECK(text.str().find('\xff') == std::string::npos);
  std::remove(path.c_str());
}

TEST_CASE(
    "WriteMel keeps comments to one line and names Maya's second, millisecond, minute and hour "
    "units",
    "[export][mel]") {
  Walk walk = test::BipedWalk();
  walk.tracks[0].name = "L\\";  // a backslash ending a comment line could join the next to it
  walk.stopped = "a\x1b[2J reason\\";
  // (A frame a minute, Maya's "min", warned that Maya had no unit for it.)
  for (const auto& [fps, unit] : {std::pair<double, std::string>{1, "sec"},
                                  {1000, "millisec"},
                                  {1.0 / 60, "min"},
                                  {1.0 / 3600, "hour"}}) {
    walk.fps = fps;
    const std::string path = WriteAndKeep(walk, "units.mel");
    CHECK(ParseMel(path).time_unit == unit);
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) {
      INFO(line);
      CHECK((line.empty() || line.back() != '\\'));
      CHECK(line.find('\x1b') == std::string::npos);
    }
    std::remove(path.c_str());
  }
}

TEST_CASE("WriteMel's header names no file but its own", "[export][mel]") {
  // It said source "walk.mel" whatever the file was called.
  const std::string path = WriteAndKeep(test::BipedWalk(), "stairs.mel");
  std::ifstream in(path);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  CHECK(second ==
        "// In Maya: source this file (File > Source Script); one keyed locator per foot IK "
        "target and body.");
  std::remove(path.c_str());
}

TEST_CASE("WriteMel names Maya's VR audio and high frame rate units", "[export][mel]") {
  Walk walk = test::BipedWalk();
  for (const auto& [fps, unit] : {std::pair<double, std::string>{90, "90fps"},
                                  {119.88, "119.88fps"},
                                  {44100, "44100fps"},
                                  {48000, "48000fps"}}) {
    INFO(fps);
    walk.fps = fps;
    const std::string path = WriteAndKeep(walk, "rare_units.mel");
    const MelScript script = ParseMel(path);
    CHECK(script.time_unit == unit);
    CHECK(script.warnings.empty());
    std::remove(path.c_str());
  }
}

TEST_CASE("WriteMel reports bad walks and unwritable paths", "[export][mel]") {
  std::string error;
  Walk walk = test::BipedWalk();
  const std::string unwritable = test::ScratchPath("no-such-dir") + "/walk.mel";
  CHECK(WriteMel(walk, unwritable, &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains(unwritable));
  walk.tracks[2].rotations[0].w = INFINITY;
  CHECK(WriteMel(walk, test::ScratchPath("bad.mel"), &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("track 2 'body' key 0 has a non-finite rotation"));
}

TEST_CASE("WriteMel keys the feet's rotations when asked, each foot on its ground",
          "[export][mel]") {
  const Walk walk = test::TiltedFootWalk();
  const std::string path = test::ScratchPath("feet.mel");
  std::string error;
  REQUIRE(WriteMel(walk, path, &error) == Status::kOk);
  MelScript script = ParseMel(path);
  CHECK(script.rotate_order.count("L") == 0);  // not unless asked
  CHECK(script.keys.at("L").count("rotateY") == 0);
  MelOptions options;
  options.foot_rotations = true;
  REQUIRE(WriteMel(walk, path, options, &error) == Status::kOk);
  script = ParseMel(path);
  CHECK(script.rotate_order.at("L") == 2);  // zxy, as bodies
  const std::vector<Vec3> euler = LocatorEuler(script, "L");
  const std::vector<test::FootAxes> axes = test::TiltedFootAxes();
  REQUIRE(euler.size() == axes.size());
  for (size_t i = 0; i < axes.size(); ++i) {
    INFO("key " << i);
    CHECK(Distance(RotateEulerZxy(euler[i], {0, 1, 0}), axes[i].up) < 1e-9);
    CHECK(Distance(RotateEulerZxy(euler[i], {0, 0, 1}), axes[i].forward) < 1e-9);
    if (i > 0) CHECK(std::abs(euler[i].y - euler[i - 1].y) < 180);
  }
  std::remove(path.c_str());
}
