// The character file and walk JSON readers (round trips, each kind of bad input named), and the
// C ABI's ffc_generate against GenerateWalk.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/client/footfall_c.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/steps/foot_rotations.h"
#include "footfall/steps/generate_request.h"
#include "footfall/steps/scene.h"
#include "footfall/steps/walk_json.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

namespace {

std::string Biped(const std::string& replace_from = "", const std::string& replace_to = "") {
  std::string text = R"({"format": "footfall-character", "version": 1, "name": "b",
    "feet": [{"name": "L", "rest": [0.1, 0, 0]}, {"name": "R", "rest": [-0.1, 0, 0]}],
    "gait": [["L"], ["R"]], "pairs": [["L", "R"]], "step_length": 0.6, "step_height": 0.1,
    "body_height": 0.9, "frames_per_step": 10, "align_to_normal": false, "reach": 1.1})";
  if (!replace_from.empty()) {
    const size_t at = text.find(replace_from);
    REQUIRE(at != std::string::npos);
    text.replace(at, replace_from.size(), replace_to);
  }
  return text;
}

}  // namespace

TEST_CASE("Character files parse, and bad ones are named", "[steps][character]") {
  Character c;
  std::string error;
  REQUIRE(ParseCharacter(Biped(), "b.json", &c, &error) == Status::kOk);
  CHECK(c.feet.size() == 2);
  CHECK(c.gait.size() == 2);
  CHECK(c.frames_per_step == 10);
  CHECK(c.max_slope_deg == 50);  // default
  CHECK(c.foot_length == 0);     // default: point feet
  REQUIRE(ParseCharacter(Biped("\"reach\": 1.1", "\"reach\": 1.1, \"foot_length\": 0.25"), "b.json",
                         &c, &error) == Status::kOk);
  CHECK(c.foot_length == 0.25);
  CHECK(c.foot_width == 0);  // default: no width
  REQUIRE(ParseCharacter(
              Biped("\"reach\": 1.1", "\"reach\": 1.1, \"foot_length\": 0.25, \"foot_width\": 0.1"),
              "b.json", &c, &error) == Status::kOk);
  CHECK(c.foot_width == 0.1);
  // A version written 1.0 is the version 1, as frames_per_step 10.0 is 10.
  CHECK(ParseCharacter(Biped("\"version\": 1", "\"version\": 1.0"), "b.json", &c, &error) ==
        Status::kOk);
  for (const std::string& name : ShippedCharacters()) LoadShipped(name);
  const std::pair<std::pair<std::string, std::string>, std::string> bad[] = {
      {{"\"version\": 1", "\"version\": 2"}, "b.json: 'version' 2 is not supported"},
      {{"\"step_length\": 0.6", "\"step_length\": -1"},
       "b.json: 'step_length' = -1 is out of range"},
      {{"\"reach\": 1.1", "\"reach\": 1.1, \"foot_length\": -0.1"},
       "b.json: 'foot_length' = -0.1 is out of range [0, 1e+09]"},
      {{"\"reach\": 1.1", "\"reach\": 1.1, \"foot_length\": \"long\""}, "b.json: 'foot_length'"},
      {{"\"reach\": 1.1", "\"reach\": 1.1, \"foot_length\": 0.2, \"foot_width\": -0.1"},
       "b.json: 'foot_width' = -0.1 is out of range [0, 1e+09]"},
      {{"\"reach\": 1.1", "\"reach\": 1.1, \"foot_width\": 0.1"},
       "b.json: 'foot_width': needs a 'foot_length' above 0"},
      {{"[[\"L\"], [\"R\"]]", "[[\"L\"], [\"X\"]]"}, "b.json: 'gait'[1]: no foot named 'X'"},
      {{"[[\"L\"], [\"R\"]]", "[[\"L\"]]"},
       "b.json: 'gait': foot 'R' is in none of them (list every foot once)"},
      {{"\"pairs\": [[\"L\", \"R\"]]", "\"pairs\": [[\"L\"]]"},
       "b.json: 'pairs': foot 'R' is in none of them (list every foot once, one alone as "
       "[\"R\"])"},
      // A misspelt foot field is named (not only the missing one it was meant to be).
      {{"{\"name\": \"R\"", "{\"nmae\": \"R\""},
       "b.json: 'feet'[1]: unknown field 'nmae' (known fields: comment, name, rest)"},
      {{"\"version\": 1", "\"version\": 1.5"}, "b.json: 'version' 1.5 is not supported"},
      // Names from the file reach no terminal with their control characters (ESC, the C1 CSI).
      {{"\"reach\": 1.1", "\"reach\": 1.1, \"\\u001b[31m\\u009b31mx\": 1"},
       "b.json: unknown field '?[31m?31mx' (known fields:"},
      {{"[[\"L\"], [\"R\"]]", "[[\"L\"], [\"R\\u009b\"]]"},
       "b.json: 'gait'[1]: no foot named 'R?'"},
      {{"[[\"L\"], [\"R\"]]", "[[\"L\", \"L\"], [\"R\"]]"}, "foot 'L' is listed twice"},
      {{"\"reach\": 1.1", "\"reach\": 0.5"},
       "'reach' = 0.5 must exceed the distance from the body to the rest of foot 'L' (0.9"},
      // Numbers are shown as written, never rounded onto the limit they break.
      {{"\"step_length\": 0.6", "\"step_length\": 1000000000.001"},
       "'step_length' = 1000000000.001 is out of range (0, 1e+09]"},
      {{"\"frames_per_step\": 10", "\"frames_per_step\": 2147483648"},
       "'frames_per_step' = 2147483648 is out of range [2, 1e+06]"},
      // (Converted to int before the check: undefined, said by UBSan.)
      {{"\"frames_per_step\": 10", "\"frames_per_step\": -1e300"},
       "'frames_per_step' = -1e+300 is out of range [2, 1e+06]"},
      // Control characters in names: a NUL cut glTF node names short, others broke MEL lines.
      {{"{\"name\": \"L\"", "{\"name\": \"L\\u0000a\""},
       "b.json: 'feet'[0].name: expected a name without control characters (byte 0x00 at offset "
       "1)"},
      {{"{\"name\": \"L\"", "{\"name\": \"L\\u0085\""},
       "'feet'[0].name: expected a name without control characters (character U+0085 at offset 1)"},
      {{"\"name\": \"b\"", "\"name\": \"b\\tc\""},
       "b.json: 'name': expected a name without control characters (byte 0x09 at offset 1)"},
      // A foot called "body" took the body's name in Blender rigs.
      {{"{\"name\": \"L\"", "{\"name\": \"body\""},
       "b.json: 'feet'[0].name: 'body' names the body's track"},
      // Rests are lengths like the others (1e300 made the reach check say "inf").
      {{"[0.1, 0, 0]", "[1e300, 0, 0]"}, "'feet'[0].rest: 1e+300 is out of range [-1e9, 1e9]"},
      {{"\"name\": \"b\"", "\"nmae\": \"b\""},
       "b.json: unknown field 'nmae' (known fields: align_to_normal, body_height, comment,"},
      {{"[0.1, 0, 0]}", "[0.1, 0, 0], \"size\": 1}"},
       "b.json: 'feet'[0]: unknown field 'size' (known fields: comment, name, rest)"},
      // The version is compared exactly: 2^32 + 1 does not wrap to 1.
      {{"\"version\": 1", "\"version\": 4294967297"},
       "b.json: 'version' 4294967297 is not supported"},
      {{"\"version\": 1", "\"version\": -4294967295"}, "'version' -4294967295 is not supported"},
      {{"\"version\": 1", "\"version\": 18446744073709551615"}, "is not supported"},
      {{"\"frames_per_step\": 10", "\"frames_per_step\": 2.5"},
       "'frames_per_step': expected an integer"},
      {{"\"align_to_normal\": false", "\"align_to_normal\": 1"},
       "'align_to_normal': expected true"},
      {{"[0.1, 0, 0]", "[0.1, 0]"}, "'feet'[0].rest: expected [x, y, z]"},
      {{"{\"name\": \"R\"", "{\"name\": \"\""}, "'feet'[1].name: expected a non-empty name"},
      // Two feet resting on one spot would have their targets and keys on top of each other.
      {{"[-0.1, 0, 0]", "[0.1, 0, 0]"},
       "b.json: 'feet'[1].rest: the same as foot 'L''s: each foot needs its own rest position"},
      {{"\"body_height\": 0.9,", ""}, "missing field 'body_height'"},
      // Fields of the wrong JSON type are named with the type found, never thrown.
      {{"\"footfall-character\"", "5"}, "b.json: 'format' must be a string, found number"},
      {{"\"format\": \"footfall-character\",", ""}, "b.json: missing field 'format'"},
      // Another format's file is named by its format, not by a field it has (a scene file given
      // as a character was "unknown field 'characters'").
      {{"\"footfall-character\"", "\"footfall-scene\", \"characters\": []"},
       "b.json: 'format': expected \"footfall-character\", found \"footfall-scene\""},
      {{"\"version\": 1,", ""}, "b.json: missing field 'version' (expected 1)"},
      {{"\"name\": \"b\"", "\"name\": [1]"}, "b.json: 'name' must be a string, found array"},
      {{"\"step_length\": 0.6", "\"step_length\": \"0.6\""},
       "b.json: 'step_length' must be a number, found string"},
  };
  for (const auto& [edit, message] : bad) {
    INFO(message);
    CHECK(ParseCharacter(Biped(edit.first, edit.second), "b.json", &c, &error) != Status::kOk);
    CHECK_THAT(error, Catch::Contains(message));
  }
  CHECK(ParseCharacter("{", "b.json", &c, &error) == Status::kParseError);
  // Syntax errors say where: line 3, column 16 is the '}' after the missing value.
  CHECK(ParseCharacter("{\"format\": \"footfall-character\",\n\"version\": 1,\n\"step_length\": }",
                       "b.json", &c, &error) == Status::kParseError);
  CHECK_THAT(error, Catch::StartsWith("b.json:3:16: malformed JSON: syntax error"));
  // Malformed too, and said so with where: a number beyond a double (nlohmann threw a bare
  // "number overflow"), a NUL byte (nlohmann read it as the end of the input), a key given twice
  // (the last one silently won).
  CHECK(ParseCharacter("{\"format\": \"footfall-character\",\n\"version\": 1e999}", "b.json", &c,
                       &error) == Status::kParseError);
  CHECK_THAT(error, Catch::StartsWith("b.json:2:12: malformed JSON: number overflow parsing "
                                      "'1e999'"));
  CHECK(ParseCharacter(std::string("{\"format\":\0 1}", 14), "b.json", &c, &error) ==
        Status::kParseError);
  CHECK_THAT(error, Catch::StartsWith("b.json:1:11: malformed JSON: a NUL byte"));
  // UTF-16 text (Windows editors' "Unicode") is named, not "a NUL byte" at its second byte.
  CHECK(ParseCharacter(std::string("\xFF\xFE{\0\"\0f\0\"\0", 10), "b.json", &c, &error) ==
        Status::kParseError);
  CHECK(error == "b.json:1: UTF-16 text (expected ASCII or UTF-8: save the file as UTF-8)");
  CHECK(ParseCharacter(Biped("\"step_length\": 0.6", "\"step_length\": 0.6, \"step_length\": -5"),
                       "b.json", &c, &error) == Status::kParseError);
  CHECK_THAT(error,
             Catch::Contains("b.json:3:72: malformed JSON: the key 'step_length' appears twice"));
  // A comment is text, at the top level and in a foot.
  CHECK(ParseCharacter(Biped("\"step_length\": 0.6", "\"step_length\": 0.6, \"comment\": 3"),
                       "b.json", &c, &error) == Status::kParseError);
  CHECK(error == "b.json: 'comment' must be a string, found number (line 3)");
  CHECK(ParseCharacter(Biped("[0.1, 0, 0]}", "[0.1, 0, 0], \"comment\": [\"left\"]}"), "b.json", &c,
                       &error) == Status::kParseError);
  CHECK(error == "b.json: 'feet'[0].comment: expected a string, found array (line 2)");
  // Keys may repeat in different objects; a foot may carry a comment as the file may.
  CHECK(ParseCharacter(Biped("[0.1, 0, 0]}", "[0.1, 0, 0], \"comment\": \"left\"}"), "b.json", &c,
                       &error) == Status::kOk);
  // A UTF-8 byte order mark is skipped.
  CHECK(ParseCharacter("\xEF\xBB\xBF" + Biped(), "b.json", &c, &error) == Status::kOk);
  CHECK(LoadCharacter("/nonexistent/c.json", &c, &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("/nonexistent/c.json: cannot open"));
}

TEST_CASE(
    "Character and scene files too large are refused before they are read, and /proc "
    "files are read whole",
    "[steps][character]") {
  // A 3 GB file took 3 GB and 14 s to be refused at its first byte; a file of /proc (whose end
  // cannot be sought) was read as empty.
  const std::string dir =
      std::filesystem::temp_directory_path() / ("footfall-large-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/large.json";
  { std::ofstream(path) << "{\"format\": \"footfall-character\""; }
  std::filesystem::resize_file(path, (uint64_t{16} << 20) + 1);  // sparse
  Character c;
  std::string error;
  CHECK(LoadCharacter(path, &c, &error) == Status::kLimitExceeded);
  CHECK(error == path + ": 16777217 bytes, more than the 16 MB a character file may have");
  std::vector<SceneCharacter> scene;
  CHECK(LoadScene(path, &scene, &error) != Status::kLimitExceeded);  // a scene may be larger
  std::filesystem::remove_all(dir);
  CHECK(LoadCharacter("/proc/self/status", &c, &error) == Status::kParseError);
  CHECK_THAT(error, Catch::StartsWith("/proc/self/status:1:1: malformed JSON") &&
                        !Catch::Contains("unexpected end of input"));
}

TEST_CASE("A character file that exists but cannot be opened is named with the reason",
          "[steps][character]") {
  // A host at its descriptor limit (a DCC with many files open): the message said only
  // "cannot open character file".
  const std::string path = std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/biped.json";
  struct rlimit old_limit;
  REQUIRE(getrlimit(RLIMIT_NOFILE, &old_limit) == 0);
  struct rlimit low_limit = old_limit;
  low_limit.rlim_cur = std::min<rlim_t>(old_limit.rlim_cur, 256);
  REQUIRE(setrlimit(RLIMIT_NOFILE, &low_limit) == 0);
  std::vector<int> taken;  // every descriptor left below the limit
  for (int fd; (fd = open("/dev/null", O_RDONLY)) >= 0;) taken.push_back(fd);
  const int full_errno = errno;
  Character c;
  std::string error;
  const Status status = LoadCharacter(path, &c, &error);
  for (int fd : taken) close(fd);
  REQUIRE(setrlimit(RLIMIT_NOFILE, &old_limit) == 0);
  REQUIRE(full_errno == EMFILE);
  CHECK(status == Status::kIoError);
  CHECK(error == path + ": cannot open character file: " + std::strerror(EMFILE));
  CHECK(LoadCharacter(path, &c, &error) == Status::kOk);  // and once descriptors are free
}

TEST_CASE("Walk JSON reads back exactly what was written", "[steps][walk_json]") {
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeHeightField(150, 150, 0.012, 0.01, 3), 0.012);
  GenerateOptions o;
  o.steps = 6;
  o.crowd = 2;
  o.crowd_spacing = 0.6;
  const Walk w = Generate(t, c, o);
  INFO(w.stopped);
  const std::string text = WalkToJson(w);
  Walk back;
  std::string error;
  REQUIRE(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  CHECK(WalkToJson(back) == text);
  REQUIRE(back.tracks.size() == w.tracks.size());
  CHECK(back.tracks[0].character == "c1");
  CHECK(back.tracks[0].keys[1].phase == KeyPhase::kMid);
  CHECK(back.tracks[0].keys[1].position == w.tracks[0].keys[1].position);
  CHECK(std::string(PhaseName(KeyPhase::kStart)) == "start");
  CHECK(std::string(PhaseName(KeyPhase::kNone)).empty());
  const std::pair<std::string, std::string> bad[] = {
      {R"({"format":"footfall-walk","version":9,"fps":24,"tracks":[]})",
       "w.json: version: expected 1"},
      {R"({"format":"footfall-walk","version":4294967297,"fps":24,"tracks":[]})",
       "w.json: version: expected 1"},
      {R"({"format":"footfall-walk","version":1,"fps":0,"tracks":[]})",
       "w.json: fps: expected a positive number"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"arm","keys":[]}]})",
       "tracks[0].kind: expected \"foot\" or \"body\""},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[{"frame":1,"phase":"up","position":[0,0,0]}]}]})",
       "tracks[0].keys[0].phase: expected"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[{"frame":1,"phase":"end","position":[0,0]}]}]})",
       "tracks[0].keys[0].position: expected an array of 3 numbers"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"b","kind":"body","keys":[{"frame":2,"position":[0,0,0]},{"frame":1,"position":[0,0,0]}]}]})",
       "tracks[0].keys[1].frame: frames must increase"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"b","kind":"body","keys":[{"frame":1,"position":[0,0,0]},{"frame":1,"position":[1,0,0]}]}]})",
       "tracks[0].keys[1].frame: frames must increase"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"b","kind":"body","keys":[{"frame":1,"position":[0,0,0],"rotation":[0,0,0,0]}]}]})",
       "w.json: tracks[0].keys[0].rotation: expected a non-zero quaternion"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[{"frame":1,"phase":"end","position":[0,0,0],"rotation":[0,0,0,0]}]}]})",
       "w.json: tracks[0].keys[0].rotation: expected a non-zero quaternion"},
      // A foot track's rotations are on all its keys or on none.
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[{"frame":1,"phase":"end","position":[0,0,0]},{"frame":2,"phase":"start","position":[0,0,0],"rotation":[0,0,0,1]}]}]})",
       "w.json: tracks[0].keys[1].rotation: expected a rotation on every key of a foot track or on "
       "none (the first key has none)"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[{"frame":1,"phase":"end","position":[0,0,0],"rotation":[0,0,0,1]},{"frame":2,"phase":"start","position":[0,0,0]}]}]})",
       "w.json: tracks[0].keys[1]: expected a rotation on every key of a foot track or on none "
       "(the first key has one)"},
      {R"({"format":5,"version":1,"fps":24,"tracks":[]})",
       "w.json: format: must be a string, found number"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"stopped":7,"tracks":[]})",
       "w.json: stopped: expected a string"},
      {"[1, 2]", "w.json: not a JSON object"},
      {"{\"format\": \"footfall-walk\",\n \"tracks\": [\n",
       "w.json:3:1: malformed JSON: syntax error"},
      // The position is the last character the parser read: the end of the unexpected "24".
      {"{\"format\": \"footfall-walk\",\n \"fps\": 24 24}",
       "w.json:2:13: malformed JSON: syntax error"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L\u001b[2J","kind":"foot","keys":[]}]})",
       "w.json: tracks[0].name: expected a name without control characters (byte 0x1b at offset "
       "1)"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"fps":30,"tracks":[]})",
       "w.json:1:48: malformed JSON: the key 'fps' appears twice"},
      // A misspelt field is named, at every level (a foot key's "normals" left its normal at
      // the default, unseen); a comment is text.
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[],"frame_rate":30})",
       "w.json: unknown field 'frame_rate' (known fields: comment, format, fps, "
       "stopped, tracks, unit, version)"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","key":[]}]})",
       "w.json: tracks[0]: unknown field 'key'"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[{"frame":1,"phase":"end","position":[0,0,0],"normals":[0,0,1]}]}]})",
       "w.json: tracks[0].keys[0]: unknown field 'normals' (known fields: comment, "
       "frame, normal, phase, position, rotation)"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"b","kind":"body","keys":[{"frame":1,"position":[0,0,0],"phase":"end"}]}]})",
       "w.json: tracks[0].keys[0]: unknown field 'phase' (known fields: comment, frame, "
       "position, rotation)"},
      // A key with an escape sequence is shown safely.
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"L","kind":"foot","keys":[],"\u001b[2J":1}]})",
       "w.json: tracks[0]: unknown field '?[2J'"},
      {R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[],"comment":{"by":"me"}})",
       "w.json: comment: expected a string, found object"},
  };
  // Comments are allowed at every level.
  CHECK(
      ParseWalkJson(
          R"({"format":"footfall-walk","version":1,"fps":24,"comment":"a","tracks":[{"name":"L","kind":"foot","comment":"b","keys":[{"frame":1,"phase":"end","position":[0,0,0],"comment":"c"}]}]})",
          "w.json", &back, &error) == Status::kOk);
  // Rotations of any non-zero length are read (readers normalise them): 1e-10 components
  // were refused as zero.
  for (const char* q : {"[0,1e-10,0,1e-10]", "[0,1e300,0,1e300]"}) {
    INFO(q);
    const std::string text =
        std::string(
            R"({"format":"footfall-walk","version":1,"fps":24,"tracks":[{"name":"b","kind":"body","keys":[{"frame":1,"position":[0,0,0],"rotation":)") +
        q + "}]}]}";
    CHECK(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  }
  for (const auto& [input, message] : bad) {
    INFO(message);
    CHECK(ParseWalkJson(input, "w.json", &back, &error) == Status::kParseError);
    CHECK_THAT(error, Catch::Contains(message));
  }
}

TEST_CASE("Foot rotations: asked for, the walk and its JSON carry each foot key's orientation",
          "[steps][walk_json][foot_rotations]") {
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeHeightField(150, 150, 0.012, 0.01, 3), 0.012);
  GenerateOptions o;
  o.steps = 6, o.crowd = 2, o.crowd_spacing = 0.6;
  const Walk plain = Generate(t, c, o);
  o.foot_rotations = true;
  const Walk turned = Generate(t, c, o);
  REQUIRE(turned.tracks.size() == plain.tracks.size());
  FootOrientation orientation(plain);
  size_t feet = 0;
  for (size_t i = 0; i < turned.tracks.size(); ++i) {
    const WalkTrack& track = turned.tracks[i];
    INFO(track.character << "/" << track.name);
    CHECK(track.keys.size() == plain.tracks[i].keys.size());
    if (track.kind == TrackKind::kBody) {
      CHECK(std::equal(track.rotations.begin(), track.rotations.end(),
                       plain.tracks[i].rotations.begin(), plain.tracks[i].rotations.end(),
                       [](const Quat& a, const Quat& b) {
                         return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w;
                       }));
      continue;
    }
    CHECK(plain.tracks[i].rotations.empty());
    REQUIRE(track.rotations.size() == track.keys.size());
    const std::vector<Quat> expected = orientation.Rotations(i);
    for (size_t k = 0; k < track.keys.size(); ++k, ++feet) {
      const Quat& q = track.rotations[k];
      CHECK(q.x == expected[k].x);
      CHECK(q.w == expected[k].w);
      // The foot's up stands on the key's normal.
      CHECK(Dot(Rotate(q, Vec3{0, 1, 0}), Normalize(track.keys[k].normal)) > 1 - 1e-9);
    }
  }
  CHECK(feet > 50);
  // Written as "rotation" on every foot key, read back exactly; without them, none.
  const std::string text = WalkToJson(turned);
  Walk back;
  std::string error;
  REQUIRE(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  CHECK(WalkToJson(back) == text);
  CHECK(back.tracks[0].rotations.size() == back.tracks[0].keys.size());
  const auto count = [](const std::string& s, const std::string& what) {
    size_t n = 0;
    for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
    return n;
  };
  CHECK(count(text, "\"rotation\"") == count(text, "\"frame\""));
  const std::string plain_text = WalkToJson(plain);
  CHECK(count(plain_text, "\"rotation\"") < count(plain_text, "\"frame\"") / 5);
  // AddFootRotations on the plain walk gives the same.
  Walk added = plain;
  AddFootRotations(&added);
  CHECK(WalkToJson(added) == text);
  // A request asks for them with "foot_rotations": true; anything but a boolean is refused,
  // and a scene's characters take it from the whole walk, not each.
  Character rc;
  GenerateOptions ro;
  const std::string file = std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/biped.json";
  REQUIRE(ParseGenerateRequest(R"({"character_file": ")" + file + R"(", "foot_rotations": true})",
                               &rc, &ro, &error) == Status::kOk);
  CHECK(ro.foot_rotations);
  CHECK(ParseGenerateRequest(R"({"character_file": ")" + file + R"(", "foot_rotations": 1})", &rc,
                             &ro, &error) == Status::kParseError);
  CHECK(error == "request: 'foot_rotations': expected true or false");
  std::vector<SceneCharacter> scene;
  const Status read = ParseScene(
      R"({"format": "footfall-scene", "version": 1, "characters": [{"character_file": ")" + file +
          R"(", "foot_rotations": true}]})",
      "s.json", "", &scene, &error);
  CHECK(read != Status::kOk);
  CHECK_THAT(error, Catch::Contains("unknown field 'foot_rotations'"));
}

TEST_CASE("ffc_generate gives the walk GenerateWalk gives", "[steps][c_api]") {
  const RawSamples ground = MakeHeightField(200, 200, 0.05, 0.05, 5);
  std::vector<double> flat;
  for (size_t i = 0; i < ground.size(); ++i) {
    const Vec3 &p = ground.points[i], &n = ground.normals[i];
    flat.insert(flat.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
  }
  ffc_session* s = ffc_open_embedded();
  REQUIRE(s);
  uint32_t terrain = 0;
  REQUIRE(ffc_load_samples(s, flat.data(), ground.size(), "hf", &terrain) == FF_C_OK);
  const std::string file = std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/biped.json";
  const std::string request =
      R"({"character_file": ")" + file +
      R"(", "start": [5, 0, 5], "heading": [1, 0, 0], "steps": 6, "start_frame": 10})";
  char* json = nullptr;
  REQUIRE(ffc_generate(s, terrain, request.c_str(), &json) == FF_C_OK);
  REQUIRE(json);
  Terrain t = LoadTerrain(ground, 0.05);
  GenerateOptions o;
  o.has_start = true, o.start = {5, 0, 5}, o.heading = {1, 0, 0}, o.steps = 6, o.start_frame = 10;
  CHECK(std::string(json) == WalkToJson(Generate(t, LoadShipped("biped"), o)));
  ffc_free_string(json);
  // A crowd's walk, some megabytes of text built in pieces: the same text.
  json = nullptr;
  const std::string crowd = R"({"character_file": ")" + file +
                            R"(", "start": [5, 0, 5], "heading": [1, 0, 0], "steps": 8,
                               "crowd": 300, "crowd_spacing": 0.45})";
  const int32_t crowd_status = ffc_generate(s, terrain, crowd.c_str(), &json);
  REQUIRE(json);
  o.steps = 8, o.crowd = 300, o.crowd_spacing = 0.45, o.start_frame = 1;
  const std::string expected = WalkToJson(Generate(t, LoadShipped("biped"), o));
  CHECK(expected.size() > 1u << 20);
  CHECK(std::string(json) == expected);
  CHECK((crowd_status == FF_C_OK) == (expected.find("\"stopped\":\"\"") != std::string::npos));
  ffc_free_string(json);
  // Bad requests: a status and a message, no walk.
  json = nullptr;
  CHECK(ffc_generate(s, terrain, R"({"steps": 3})", &json) == FF_C_INVALID_ARGUMENT);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("'character'"));
  CHECK(json == nullptr);
  CHECK(ffc_generate(s, terrain, "{", &json) == FF_C_PARSE_ERROR);
  CHECK(ffc_generate(s, terrain, nullptr, &json) == FF_C_INVALID_ARGUMENT);
  // A walk stopped early: FF_C_NO_FOOTHOLD, the keys so far, and why in ffc_last_error.
  const std::string cliff = R"({"character_file": ")" + file +
                            R"(", "start": [5, 0, 5], "heading": [1, 0, 0], "steps": 200})";
  REQUIRE(ffc_generate(s, terrain, cliff.c_str(), &json) == FF_C_NO_FOOTHOLD);
  REQUIRE(json);
  CHECK_THAT(std::string(json), Catch::Contains("\"phase\":\"end\""));
  CHECK_THAT(ffc_last_error(s), Catch::StartsWith("step "));
  // Stopped at the terrain, not by a failed server (ffc_walk_stop tells them apart).
  CHECK(ffc_walk_stop(s) == FF_C_NO_FOOTHOLD);
  ffc_free_string(json);
  // A walk that did not stop, and a request refused: nothing stopped.
  const std::string short_walk = R"({"character_file": ")" + file +
                                 R"(", "start": [5, 0, 5], "heading": [1, 0, 0], "steps": 2})";
  REQUIRE(ffc_generate(s, terrain, short_walk.c_str(), &json) == FF_C_OK);
  CHECK(ffc_walk_stop(s) == FF_C_OK);
  ffc_free_string(json);
  CHECK(ffc_walk_stop(nullptr) == FF_C_INVALID_ARGUMENT);
  // A request's unit (--unit) is its walk's, said in the JSON; one it does not know is refused.
  const std::string in_metres =
      R"({"character_file": ")" + file + R"(", "start": [5, 0, 5], "steps": 2, "unit": "m"})";
  REQUIRE(ffc_generate(s, terrain, in_metres.c_str(), &json) == FF_C_OK);
  CHECK_THAT(std::string(json),
             Catch::StartsWith(R"({"format":"footfall-walk","version":1,"fps":24,"unit":"m",)"));
  ffc_free_string(json);
  json = nullptr;
  const std::string in_furlongs =
      R"({"character_file": ")" + file + R"(", "start": [5, 0, 5], "steps": 2, "unit": "furlong"})";
  CHECK(ffc_generate(s, terrain, in_furlongs.c_str(), &json) == FF_C_PARSE_ERROR);
  CHECK_THAT(ffc_last_error(s),
             Catch::Contains("request: 'unit': expected one of mm, cm, m, km, in, ft, yd or mi"));
  CHECK(json == nullptr);
  ffc_close(s);
}

TEST_CASE("The C ABI refuses what would crash or hang it, and takes turns between threads",
          "[steps][c_api]") {
  ffc_session* s = ffc_open_embedded();
  REQUIRE(s);
  char* json = nullptr;
  // A request nested 100,000 deep (serialising it again recursed once per level: a crash).
  const std::string deep =
      "{\"character\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  CHECK(ffc_generate(s, 0, deep.c_str(), &json) == FF_C_PARSE_ERROR);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("nested deeper than"));
  CHECK(json == nullptr);
  // Malformed JSON says where; integers out of range are refused, not wrapped.
  CHECK(ffc_generate(s, 0, R"({"steps": 3,})", &json) == FF_C_PARSE_ERROR);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("request:1:13: malformed JSON"));
  CHECK(ffc_generate(s, 0, R"({"steps": 1e999})", &json) == FF_C_PARSE_ERROR);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("request:1:11: malformed JSON: number overflow"));
  CHECK(ffc_generate(s, 0, R"({"steps": 3, "steps": 4})", &json) == FF_C_PARSE_ERROR);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("the key 'steps' appears twice"));
  const std::string file = std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/biped.json";
  for (const char* field :
       {R"("steps": 18446744073709551615)", R"("steps": -1)", R"("crowd": 0)", R"("crowd": -1)",
        R"("fps": 1e-300)", R"("crowd_spacing": 1e308)", R"("start_frame": -1e10)"}) {
    const std::string request = R"({"character_file": ")" + file + "\", " + field + "}";
    INFO(request);
    CHECK(ffc_generate(s, 0, request.c_str(), &json) == FF_C_PARSE_ERROR);
    CHECK_THAT(ffc_last_error(s), Catch::Contains("out of range") || Catch::Contains("from "));
  }
  // A NUL in a character file's path: refused (the path was read cut short at it).
  const std::string nul = R"({"character_file": ")" + file + R"(\u0000junk"})";
  CHECK(ffc_generate(s, 0, nul.c_str(), &json) == FF_C_PARSE_ERROR);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("without NUL bytes"));
  // A character file that is a FIFO: refused at once (opening it waited for a writer).
  char dir[] = "/tmp/footfall-fifo-XXXXXX";
  REQUIRE(mkdtemp(dir));
  const std::string fifo = std::string(dir) + "/character.json";
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  const std::string request = R"({"character_file": ")" + fifo + "\"}";
  CHECK(ffc_generate(s, 0, request.c_str(), &json) == FF_C_INVALID_ARGUMENT);
  CHECK_THAT(ffc_last_error(s), Catch::Contains("a FIFO, not a regular file"));
  unlink(fifo.c_str());
  rmdir(dir);
  // Counts no memory can hold: a limit, not an internal error.
  double point[3] = {0, 0, 0};
  ffc_foothold out[1];
  CHECK(ffc_snap(s, 0, point, ~size_t{0} / 2, out) == FF_C_LIMIT_EXCEEDED);
  // Timeouts without a bound are refused.
  CHECK(ffc_open_rpc(nullptr, 9, std::nan("")) == nullptr);
  CHECK(ffc_open_rpc(nullptr, 9, HUGE_VAL) == nullptr);
  CHECK(ffc_open_rpc(nullptr, 9, -HUGE_VAL) == nullptr);
  CHECK(ffc_open_rpc(nullptr, 9, 1e300) == nullptr);
  // A server-side path longer than the protocol carries: refused before any call is made.
  ffc_session* rpc = ffc_open_rpc(nullptr, 9, 1);
  REQUIRE(rpc);
  uint32_t terrain = 0;
  CHECK(ffc_load_server_file(rpc, std::string(5000, 'a').c_str(), 0, &terrain) ==
        FF_C_INVALID_ARGUMENT);
  CHECK_THAT(ffc_last_error(rpc), Catch::Contains("at most 1024 bytes"));
  ffc_close(rpc);
  // Four threads failing calls on one session and reading its error (the error string was
  // shared unguarded: heap corruption).
  std::vector<std::thread> threads;
  std::atomic<int> wrong{0};
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 2000; ++i) {
        uint32_t handle = 0;
        const std::string missing = "/nonexistent/" + std::to_string(t) + ".pts";
        if (ffc_load_file(s, missing.c_str(), 0, &handle) != FF_C_IO_ERROR) ++wrong;
        if (std::string(ffc_last_error(s)).find("cannot open") == std::string::npos) ++wrong;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  CHECK(wrong == 0);
  ffc_close(s);
}
