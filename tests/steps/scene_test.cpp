// Scene files (scene.h): what they read, the errors they name, and how their characters' walks
// become one walk.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "footfall/import/terrain_generators.h"
#include "footfall/steps/scene.h"
#include "generator_fixtures.h"

using namespace footfall;
using namespace footfall::test;

namespace {

const std::string kCharacters = std::string(FOOTFALL_SOURCE_DIR) + "/data/characters";

// ParseScene of `text` with the shipped characters' folder; the message, or "" when it reads.
std::string SceneError(const std::string& text, std::vector<SceneCharacter>* scene = nullptr) {
  std::vector<SceneCharacter> read;
  std::string error;
  const Status status = ParseScene(text, "s.json", kCharacters, scene ? scene : &read, &error);
  if (status == Status::kOk) return "";
  CHECK_FALSE(error.empty());
  return error;
}

std::string Scene(const std::string& characters) {
  return R"({"format": "footfall-scene", "version": 1, "characters": [)" + characters + "]}";
}

}  // namespace

TEST_CASE("A scene file reads each character with its own options", "[steps][scene]") {
  std::vector<SceneCharacter> scene;
  REQUIRE(SceneError(Scene(R"({"name": "walker", "character_file": "biped.json",
                                "start": [1, 2, 3], "path": [[1, 0, 5], [5, 0, 5]]},
                               {"character_file": "hexapod.json", "steps": 12, "crowd": 4,
                                "crowd_spacing": 0.5, "start_frame": 25, "up": [0, 0, 1]},
                               {"character_file": ")" +
                           kCharacters + R"(/octopod.json", "heading": [1, 0, 0]})"),
                     &scene) == "");
  REQUIRE(scene.size() == 3);
  CHECK(scene[0].name == "walker");
  CHECK(scene[0].character.name == "biped");
  CHECK(scene[0].character_file == kCharacters + "/biped.json");
  CHECK(scene[0].options.has_start);
  CHECK(scene[0].options.start.z == 3);
  CHECK(scene[0].options.path.size() == 2);
  CHECK_FALSE(scene[0].has_start_frame);
  CHECK_FALSE(scene[0].has_up);
  // Unnamed characters take their character's name and their place in the list.
  CHECK(scene[1].name == "hexapod2");
  CHECK(scene[1].options.steps == 12);
  CHECK(scene[1].options.crowd == 4);
  CHECK(scene[1].options.crowd_spacing == 0.5);
  CHECK(scene[1].has_start_frame);
  CHECK(scene[1].options.start_frame == 25);
  CHECK(scene[1].has_up);
  CHECK(scene[2].name == "octopod3");
  CHECK(scene[2].character_file == kCharacters + "/octopod.json");  // absolute: as given
  CHECK(scene[2].options.heading.x == 1);
}

TEST_CASE("Scene and character field errors name the field's line", "[steps][scene]") {
  // (Only syntax errors and walk files named a line.)
  const std::string scene = R"({"format": "footfall-scene", "version": 1, "characters": [
    {"character_file": "biped.json"},
    {"character_file": "biped.json",
     "strat": [1, 0, 1]},
    {"character_file": "biped.json",
     "path": [[1, 0, 1],
              [2, 0]]}]})";
  CHECK_THAT(SceneError(scene), Catch::StartsWith("s.json: characters[1]: unknown field 'strat'") &&
                                    Catch::EndsWith(" (line 4)"));
  std::string fixed = scene;
  fixed.replace(fixed.find("strat"), 5, "start");
  CHECK(SceneError(fixed) == "s.json: characters[2]: 'path[1]': expected [x, y, z] (line 7)");
  // A waypoint beyond the reach of queries too (the generator's message named no file, field
  // or line, and counted waypoints from 1).
  fixed.replace(fixed.find("[2, 0]"), 6, "[2, 0, -3e15]");
  CHECK(SceneError(fixed) ==
        "s.json: characters[2]: 'path[1]': (2, 0, -3e+15) has a coordinate beyond +-1e+15 (the "
        "reach of terrain queries) (line 7)");
  // A start too (past 1.3e154 a mesh resampled around it was "no samples").
  fixed.replace(fixed.find("[1, 0, 1]"), 9, "[1e155, 0, 1]");
  CHECK(SceneError(fixed) ==
        "s.json: characters[1]: 'start' is too far from the terrain to snap (queries reach 1e15 "
        "from it) (line 4)");
  CHECK(SceneError(R"({"format": "footfall-scene", "version": 1, "characters": [
    {"character_file": "biped.json"},
    3]})") == "s.json: characters[1]: expected an object (line 3)");
  // A character given in the entry: the line of its field in the scene file (its object was
  // read again from one line, and every error said "(line 1)").
  CHECK_THAT(SceneError(R"({"format": "footfall-scene", "version": 1, "characters": [
    {"character": {"format": "footfall-character", "version": 1,
       "feet": [{"name": "L", "rest": [0.1, 0, 0]}, {"name": "R", "rest": [-0.1, 0, 0]}],
       "gait": [["L"], ["R"]], "step_length": 0.5, "step_height": 0.1, "body_height": 1,
       "frames_per_step": 10, "align_to_normal": false,
       "reach": -1}}]})"),
             Catch::StartsWith("s.json: characters[0] character: 'reach'") &&
                 Catch::EndsWith(" (line 6)"));
  // A character file's own line, whichever reads it.
  Character c;
  std::string error;
  CHECK(ParseCharacter(R"({"format": "footfall-character", "version": 1,
    "feet": [{"name": "L", "rest": [0.1, 0, 0]}, {"name": "R", "rest": [-0.1, 0, 0]}],
    "gait": [["L"], ["R"]],
    "step_length": 0.5, "step_height": 0.1, "body_height": 1,
    "frames_per_step": 2.5,
    "align_to_normal": false, "reach": 1.2})",
                       "c.json", &c, &error) != Status::kOk);
  CHECK_THAT(error, Catch::StartsWith("c.json: 'frames_per_step'") && Catch::EndsWith(" (line 5)"));
  CHECK(ParseCharacter(R"({"format": "footfall-character", "version": 1,
    "feet": [{"name": "L", "rest": [0.1, 0, 0]},
             {"name": "R", "rest": [-0.1, 0, 0], "size": 2}],
    "gait": [["L"], ["R"]]})",
                       "c.json", &c, &error) != Status::kOk);
  CHECK_THAT(error, Catch::EndsWith(" (line 3)"));
}

TEST_CASE("A character file without a name is named after the file", "[steps][scene]") {
  // (Messages said "resampled for  at ...", and scene characters were named "1", "2".)
  const std::string dir =
      std::filesystem::temp_directory_path() / ("footfall-noname-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ifstream biped(kCharacters + "/biped.json");
  nlohmann::json j = nlohmann::json::parse(biped);
  j.erase("name");
  std::ofstream(dir + "/noname.json") << j.dump();
  Character c;
  std::string error;
  REQUIRE(LoadCharacter(dir + "/noname.json", &c, &error) == Status::kOk);
  CHECK(c.name == "noname");
  std::vector<SceneCharacter> scene;
  const std::string text =
      Scene(R"({"character_file": "noname.json"}, {"character_file": "noname.json"})");
  REQUIRE(ParseScene(text, "s.json", dir, &scene, &error) == Status::kOk);
  CHECK(scene[0].name == "noname1");
  CHECK(scene[1].name == "noname2");
  std::filesystem::remove_all(dir);
}

TEST_CASE("Scene steps and crowd written as whole decimals read as integers", "[steps][scene]") {
  // Python's json writes a float 20.0 as "20.0", as character files' frames_per_step may be.
  std::vector<SceneCharacter> scene;
  REQUIRE(SceneError(Scene(R"({"character_file": "biped.json", "steps": 20.0, "crowd": 4e0})"),
                     &scene) == "");
  CHECK(scene[0].options.steps == 20);
  CHECK(scene[0].options.crowd == 4);
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "steps": 2.5})")),
             Catch::Contains("characters[0]: 'steps': expected an integer"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "crowd": 1e300})")),
             Catch::Contains("characters[0]: 'crowd': out of range (expected 1 to 1000000)"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "steps": -1.0})")),
             Catch::Contains("characters[0]: 'steps': out of range (expected 0 to 1000000)"));
}

TEST_CASE("Scene file errors name the file the character and the field", "[steps][scene]") {
  CHECK_THAT(SceneError("[]"), Catch::StartsWith("s.json: not a JSON object"));
  CHECK_THAT(SceneError(R"({"format": "footfall-walk", "version": 1, "characters": []})"),
             Catch::EndsWith("'format': expected \"footfall-scene\", found \"footfall-walk\": "
                             "a walk file, which footfall generate writes (line 1)"));
  // A character or walk file given as a scene is told by its format, before its fields (it was
  // refused for one of its own, "unknown field 'align_to_normal'").
  std::ifstream biped(kCharacters + "/biped.json");
  const std::string biped_text((std::istreambuf_iterator<char>(biped)),
                               std::istreambuf_iterator<char>());
  CHECK(SceneError(biped_text) ==
        "s.json: 'format': expected \"footfall-scene\", found \"footfall-character\": a "
        "character file (give it with --character) (line 2)");
  CHECK(SceneError(R"({"fps": 24, "tracks": []})") ==
        "s.json: 'format': expected \"footfall-scene\", found no 'format' (line 1)");
  CHECK_THAT(SceneError(R"({"format": "footfall-scene", "version": 2, "characters": []})"),
             Catch::Contains("'version' must be 1"));
  CHECK_THAT(SceneError(R"({"format": "footfall-scene", "version": 1, "characters": []})"),
             Catch::Contains("'characters' must be an array of 1 to"));
  CHECK_THAT(SceneError(R"({"format": "footfall-scene", "version": 1, "characters": [],
                            "speed": 2})"),
             Catch::Contains("unknown field 'speed'"));
  CHECK_THAT(SceneError(Scene("3")), Catch::Contains("s.json: characters[0]: expected an object"));
  CHECK_THAT(SceneError(Scene(R"({"start": [0, 0, 0]})")),
             Catch::Contains("characters[0]: give exactly one of 'character'"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json"},
                                 {"character_file": "biped.json", "start": [0, 0]})")),
             Catch::Contains("s.json: characters[1]: 'start': expected [x, y, z]"));
  // The walk has one frame rate: --fps.
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "fps": 30})")),
             Catch::Contains("characters[0]: unknown field 'fps'"));
  // And one unit: --unit.
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "unit": "cm"})")),
             Catch::Contains("characters[0]: unknown field 'unit'"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "crowd": 0})")),
             Catch::Contains("characters[0]: 'crowd': out of range"));
  // An empty path was taken for none (the command line refuses --path "").
  for (const char* path : {"[]", "{}", "[0, 0, 1]"})
    CHECK_THAT(
        SceneError(Scene(R"({"character_file": "biped.json", "path": )" + std::string(path) + "}")),
        Catch::Contains("characters[0]: 'path': expected"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "path": []})")),
             Catch::Contains("'path': expected an array of at least one waypoint [x, y, z]"));
  // One waypoint written flat is told so, and a bad waypoint by its place (both said
  // "'path': expected [x, y, z]", what a flat one is).
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "path": [20, 0, 25]})")),
             Catch::EndsWith("characters[0]: 'path': expected an array of waypoints, [[x, y, "
                             "z], ...] (one waypoint is [[x, y, z]]) (line 1)"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "path": [[1, 0, 1], [2, 0]]})")),
             Catch::EndsWith("characters[0]: 'path[1]': expected [x, y, z] (line 1)"));
  CHECK_THAT(
      SceneError(Scene(R"({"character_file": "biped.json"}, {"character_file": "nothere.json"})")),
      Catch::StartsWith("s.json: characters[1]: " + kCharacters + "/nothere.json: cannot open"));
  CHECK_THAT(SceneError(Scene(R"({"character_file": ""})")),
             Catch::Contains("characters[0]: 'character_file': expected a path (not empty"));
  CHECK_THAT(SceneError(Scene(R"({"name": "a", "character_file": "biped.json"},
                                 {"name": "a", "character_file": "quadruped.json"})")),
             Catch::Contains("characters[1]: the name 'a' is another character's"));
  // An unnamed character's name is made up: the message says so, not that it gave that name.
  CHECK_THAT(SceneError(Scene(R"({"name": "biped2", "character_file": "biped.json"},
                                 {"character_file": "biped.json"})")),
             Catch::Contains("characters[1]: the name 'biped2' is another character's (it has "
                             "no 'name', and is named after its character file's name"));
  // A start frame beyond the flag's bounds names its field (it was refused later, naming
  // only the character and every bound of the start, the frame and the fps at once).
  CHECK_THAT(SceneError(Scene(R"({"character_file": "biped.json", "start_frame": 1e10})")),
             Catch::Contains("s.json: characters[0]: 'start_frame': expected a number from "
                             "-1e+09 to 1e+09"));
  CHECK(SceneError(Scene(R"({"character_file": "biped.json", "start_frame": -1e9})")) == "");
  CHECK_THAT(SceneError(Scene(R"({"name": "a/b", "character_file": "biped.json"})")),
             Catch::Contains("'name': a name without '/'"));
  CHECK_THAT(SceneError(Scene(R"({"name": "", "character_file": "biped.json"})")),
             Catch::Contains("'name' must be a non-empty string"));
  CHECK_THAT(SceneError(Scene(R"({"name": "a\nb", "character_file": "biped.json"})")),
             Catch::Contains("control characters"));
}

TEST_CASE("A scene character named after a character with a slash is no crowd's member",
          "[steps][scene]") {
  // A character file named "x/c" gave "x/c1", the name of crowd "x"'s first character: two
  // characters' tracks shared it, exit 0.
  std::vector<SceneCharacter> scene;
  std::string error;
  const std::string text = Scene(
      R"({"character": {"format": "footfall-character", "version": 1, "name": "x/c",
                         "feet": [{"name": "L", "rest": [0.1, 0, 0]},
                                  {"name": "R", "rest": [-0.1, 0, 0]}],
                         "gait": [["L"], ["R"]], "step_length": 0.7, "step_height": 0.15,
                         "body_height": 0.95, "frames_per_step": 12, "reach": 1.2,
                         "align_to_normal": false}},
          {"name": "x", "character_file": "biped.json", "crowd": 2})");
  const Status status = ParseScene(text, "s.json", kCharacters, &scene, &error);
  INFO(error);
  REQUIRE(status == Status::kOk);
  CHECK(scene[0].name == "x_c1");
  CHECK(scene[1].name == "x");
}

TEST_CASE("LoadScene reads character files beside the scene file", "[steps][scene]") {
  std::vector<SceneCharacter> scene;
  std::string error;
  CHECK(LoadScene(kCharacters + "/no-such-scene.json", &scene, &error) != Status::kOk);
  CHECK_THAT(error, Catch::Contains("no-such-scene.json"));
  // A scene in a folder of its own, naming a character file beside it.
  const std::string folder = std::string(FOOTFALL_BINARY_DIR) + "/scene-test";
  REQUIRE(std::system(("mkdir -p '" + folder + "' && cp '" + kCharacters + "/quadruped.json' '" +
                       folder + "/four.json'")
                          .c_str()) == 0);
  {
    std::ofstream out(folder + "/scene.json");
    out << Scene(R"({"character_file": "four.json", "steps": 3})");
  }
  REQUIRE(LoadScene(folder + "/scene.json", &scene, &error) == Status::kOk);
  REQUIRE(scene.size() == 1);
  CHECK(scene[0].character.name == "quadruped");
  CHECK(scene[0].character_file == folder + "/four.json");
  CHECK(scene[0].name == "quadruped1");
}

TEST_CASE("A scene's walk holds every character's tracks under its name", "[steps][scene]") {
  Walk one;
  one.tracks.resize(2);
  one.tracks[0].name = "L", one.tracks[0].foot_length = 0.22;
  one.tracks[1].name = "body", one.tracks[1].kind = TrackKind::kBody;
  Walk crowd;
  crowd.tracks.resize(2);
  crowd.tracks[0].name = "L1", crowd.tracks[0].character = "c1";
  crowd.tracks[1].name = "L1", crowd.tracks[1].character = "c2";
  crowd.stopped = "step 3 of c2: no foothold";
  crowd.stops = {"step 3 of c2: no foothold"};
  crowd.notes = {"c1: the goal is 2 away"};
  Walk scene;
  AddToSceneWalk("walker", std::move(one), &scene);
  CHECK(scene.stopped.empty());
  AddToSceneWalk("bugs", std::move(crowd), &scene);
  REQUIRE(scene.tracks.size() == 4);
  CHECK(scene.tracks[0].character == "walker");
  CHECK(scene.tracks[0].foot_length == 0.22);  // the sole the viewer draws goes along
  CHECK(scene.tracks[1].character == "walker");
  CHECK(scene.tracks[2].character == "bugs/c1");
  CHECK(scene.tracks[3].character == "bugs/c2");
  CHECK(scene.stopped == "bugs: step 3 of c2: no foothold");
  CHECK(scene.notes == std::vector<std::string>{"bugs: c1: the goal is 2 away"});
  Walk stopped;
  stopped.stopped = "step 1: a cliff";
  AddToSceneWalk("third", std::move(stopped), &scene);
  CHECK(scene.stops.size() == 2);
  CHECK(scene.stopped == "bugs: step 3 of c2: no foothold (and 1 more stopped)");
}

TEST_CASE("A scene's engine failures are said in the scene's order, before terrain stops",
          "[steps][scene]") {
  // (Each failure went to the front: the last character's was said first.)
  auto failed_walk = [](const std::string& reason) {
    Walk w;
    w.tracks.resize(1);
    w.tracks[0].name = "L";
    w.stopped = reason;
    w.stops = {reason};
    w.session_failed = true;
    w.failed_stops = 1;
    return w;
  };
  Walk stopped;
  stopped.tracks.resize(1);
  stopped.tracks[0].name = "L";
  stopped.stopped = "step 2: a cliff";
  stopped.stops = {"step 2: a cliff"};
  Walk crowd;  // a crowd whose two members the engine failed, after one stopped at the terrain
  crowd.tracks.resize(1);
  crowd.tracks[0].name = "L1", crowd.tracks[0].character = "c1";
  crowd.stops = {"c1: footfalld died", "c2: footfalld died", "step 1 of c3: a cliff"};
  crowd.stopped = crowd.stops.front();
  crowd.session_failed = true;
  crowd.failed_stops = 2;
  Walk scene;
  AddToSceneWalk("cliff", std::move(stopped), &scene);
  AddToSceneWalk("first", failed_walk("footfalld died"), &scene);
  AddToSceneWalk("crowd", std::move(crowd), &scene);
  AddToSceneWalk("last", failed_walk("footfalld died"), &scene);
  CHECK(scene.session_failed);
  CHECK(scene.failed_stops == 4);
  CHECK(scene.stops ==
        std::vector<std::string>{"first: footfalld died", "crowd: c1: footfalld died",
                                 "crowd: c2: footfalld died", "last: footfalld died",
                                 "cliff: step 2: a cliff", "crowd: step 1 of c3: a cliff"});
  CHECK(scene.stopped == "first: footfalld died (and 5 more stopped)");
}

TEST_CASE("Scene characters started on top of each other are said in notes", "[steps][scene]") {
  // Two characters given one start walked as one without a word (a crowd keeps its own apart).
  const Character biped = LoadShipped("biped");
  const Character quadruped = LoadShipped("quadruped");
  Terrain t = LoadTerrain(MakeFlat(201, 0.05, 0), 0.05);
  const Walk a = Generate(t, quadruped, StartOptions({5, 0, 3}, 2));
  const Walk b = Generate(t, biped, StartOptions({5.1, 0, 3}, 2));
  const Walk far = Generate(t, biped, StartOptions({8, 0, 3}, 2));
  const std::vector<std::string> notes =
      OverlappingStartNotes({"a", "b", "gone", "far"}, {&a, &b, nullptr, &far},
                            {quadruped.reach, biped.reach, biped.reach, biped.reach});
  REQUIRE(notes.size() == 1);
  CHECK_THAT(notes[0], Catch::StartsWith("a and b start 0.1") &&
                           Catch::EndsWith(" apart, under a quarter of their reach: they walk "
                                           "through each other (give them starts farther "
                                           "apart)"));
}

TEST_CASE("A character on a crowd's later member is said, the crowd's own members not",
          "[steps][scene]") {
  // (Only a crowd's first member was compared: a character started on its third went
  // unsaid.)
  const Character biped = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(201, 0.05, 0), 0.05);
  GenerateOptions o = StartOptions({3, 0, 3}, 2);
  o.crowd = 4;
  o.crowd_spacing = 1.5;
  const Walk crowd = Generate(t, biped, o);
  REQUIRE(crowd.stopped.empty());
  // Where each member stands: its first feet's centroid.
  std::map<std::string, std::pair<Vec3, int>> at;
  for (const WalkTrack& track : crowd.tracks) {
    if (track.kind != TrackKind::kFoot) continue;
    at[track.character].first += track.keys.front().position;
    ++at[track.character].second;
  }
  REQUIRE(at.size() == 4);
  const Vec3 third = at["c3"].first / static_cast<double>(at["c3"].second);
  const Walk lone = Generate(t, biped, StartOptions(third + Vec3{0.05, 0, 0}, 2));
  REQUIRE(lone.stopped.empty());
  const std::vector<std::string> notes =
      OverlappingStartNotes({"bugs", "lone"}, {&crowd, &lone}, {biped.reach, biped.reach});
  REQUIRE(notes.size() == 1);
  CHECK_THAT(notes[0], Catch::StartsWith("bugs/c3 and lone start 0.0") &&
                           Catch::Contains("they walk through each other"));
  // The crowd alone: its members stand apart (1.5 > a quarter of the reach) and are not
  // compared with each other anyway.
  CHECK(OverlappingStartNotes({"bugs"}, {&crowd}, {biped.reach}).empty());
}

TEST_CASE("Overlapping start notes name a few pairs and count the others", "[steps][scene]") {
  // 4000 characters at one start made every pair a note: 8 million, 2.8 GB.
  const Character biped = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(101, 0.05, 0), 0.05);
  const Walk one = Generate(t, biped, StartOptions({2.5, 0, 2.5}, 1));
  constexpr size_t kStarts = 300;  // 44,850 pairs
  const std::vector<std::string> names(kStarts, "x");
  const std::vector<const Walk*> walks(kStarts, &one);
  const std::vector<double> reaches(kStarts, biped.reach);
  const std::vector<std::string> notes = OverlappingStartNotes(names, walks, reaches);
  REQUIRE(notes.size() == kMaxOverlappingStartNotes + 1);
  CHECK_THAT(notes[0], Catch::StartsWith("x and x start 0 apart"));
  const size_t pairs = kStarts * (kStarts - 1) / 2;
  CHECK(notes.back() == "... and " + std::to_string(pairs - kMaxOverlappingStartNotes) +
                            " more pairs of characters start under a quarter of their reach apart");
}
