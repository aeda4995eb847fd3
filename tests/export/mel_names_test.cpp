// Locator names of the MEL export in crowds and scenes: a track whose character and name are
// legal Maya names as given keeps its name (character_name) before a name made legal, as a
// single character's track does.
#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/export/mel_writer.h"
#include "walk_fixtures.h"

using namespace footfall;

namespace {

// locator name -> footfallTrack value, and the locators in the order the script makes them.
struct Locators {
  std::vector<std::string> names;
  std::map<std::string, std::string> track_of;
};

Locators WriteAndReadLocators(const Walk& walk, const std::string& file) {
  const std::string path = test::ScratchPath(file);
  std::string error;
  REQUIRE(WriteMel(walk, path, &error) == Status::kOk);
  std::ifstream in(path);
  REQUIRE(in.good());
  static const std::regex locator(R"re(^\$footfall_node = `spaceLocator -n "(\w+)"`;$)re");
  static const std::regex track(
      R"re(^setAttr -type "string" \(\$footfall_node\[0\] \+ ".footfallTrack"\) "(.*)";$)re");
  Locators out;
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, locator)) out.names.push_back(m[1]);
    if (std::regex_match(line, m, track)) {
      REQUIRE(!out.names.empty());
      out.track_of[out.names.back()] = m[1];
    }
  }
  std::remove(path.c_str());
  return out;
}

// CrowdWalk with characters renamed `first` and `second`, and the first two feet of each
// renamed `foot0` and `foot1`.
Walk RenamedCrowd(const std::string& first, const std::string& second, const std::string& foot0,
                  const std::string& foot1) {
  Walk walk = test::CrowdWalk();
  for (WalkTrack& track : walk.tracks) {
    track.character = track.character == "ant 1" ? first : second;
    if (track.name == "L1") track.name = foot0;
    if (track.name == "R1") track.name = foot1;
  }
  return walk;
}

}  // namespace

TEST_CASE("WriteMel lets a crowd track legal as given keep its name before a sanitised one",
          "[export][mel]") {
  SECTION("crowd characters c1 and c2") {
    // A crowd of characters with feet 'left foot' and 'left_foot': as for one character, the
    // foot named left_foot is c1_left_foot (it was c1_left_foot_2, the sanitised 'left foot'
    // having taken its name, so the same foot had another name in a crowd).
    const Locators locators = WriteAndReadLocators(
        RenamedCrowd("c1", "c2", "left foot", "left_foot"), "crowd_claims.mel");
    CHECK(locators.names == std::vector<std::string>{"c1_left_foot_2", "c1_left_foot", "c1_body",
                                                     "c2_left_foot_2", "c2_left_foot", "c2_body"});
    CHECK(locators.track_of.at("c1_left_foot") == "c1/left_foot");
    CHECK(locators.track_of.at("c1_left_foot_2") == "c1/left foot");
    CHECK(locators.track_of.at("c2_left_foot") == "c2/left_foot");
  }
  SECTION("a scene's crowd, named name/cN") {
    const Locators locators = WriteAndReadLocators(
        RenamedCrowd("dogs/c1", "dogs/c2", "left foot", "left_foot"), "scene_claims.mel");
    CHECK(locators.track_of.at("dogs_c1_left_foot") == "dogs/c1/left_foot");
    CHECK(locators.track_of.at("dogs_c1_left_foot_2") == "dogs/c1/left foot");
  }
  SECTION("a character name made legal does not claim first") {
    // 'ant 1' is made legal (ant_1): its tracks are sanitised names, and a track of a character
    // legal as given that comes out the same keeps the name.
    const Locators locators =
        WriteAndReadLocators(RenamedCrowd("ant 1", "ant_1", "L1", "R1"), "made_legal.mel");
    CHECK(locators.track_of.at("ant_1_L1") == "ant_1/L1");
    CHECK(locators.track_of.at("ant_1_L1_2") == "ant 1/L1");
  }
  SECTION("a track with no name does not claim first") {
    // Its name, track<i>, is made up: a foot named track0 keeps its own.
    Walk walk = test::BipedWalk();
    walk.tracks[0].name = "";
    walk.tracks[1].name = "track0";
    const Locators locators = WriteAndReadLocators(walk, "unnamed.mel");
    CHECK(locators.track_of.at("track0") == "track0");
    CHECK(locators.track_of.at("track0_2") == "track0");
    CHECK(locators.names == std::vector<std::string>{"track0_2", "track0", "body"});
  }
}
