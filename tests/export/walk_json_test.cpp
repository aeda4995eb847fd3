// The walk JSON writer with walks built by hand: whatever the order of a track's keys, the text
// reads back, holding the keys the glTF and MEL exporters key.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <catch2/catch.hpp>

#include "footfall/steps/walk_json.h"
#include "walk_fixtures.h"

using namespace footfall;

TEST_CASE("WalkToJson writes keys that read back whatever their order", "[export][walk_json]") {
  Walk walk = test::BipedWalk();  // R's keys 2 and 3 share frame 25
  // The body's keys out of order: frame 25 written first.
  WalkTrack& body = walk.tracks[2];
  std::swap(body.keys[0], body.keys[2]);
  std::swap(body.rotations[0], body.rotations[2]);
  const std::string text = WalkToJson(walk);
  Walk back;
  std::string error;
  REQUIRE(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  INFO(error);
  REQUIRE(back.tracks.size() == 3);

  SECTION("keys on one frame: the later one kept") {
    const WalkTrack& right = back.tracks[1];
    REQUIRE(right.keys.size() == 5);
    CHECK(right.keys[2].frame == 25);
    CHECK(right.keys[2].phase == KeyPhase::kStart);  // the start after the end on frame 25
    CHECK(right.keys[3].frame == 31);
  }
  SECTION("keys out of order: written in ascending frames with their rotations") {
    const WalkTrack& b = back.tracks[2];
    REQUIRE(b.keys.size() == 5);
    for (size_t i = 0; i < b.keys.size(); ++i) {
      INFO("key " << i);
      const size_t original = i == 0 ? 2 : i == 2 ? 0 : i;
      CHECK(b.keys[i].frame == body.keys[original].frame);
      CHECK(b.keys[i].position == body.keys[original].position);
      CHECK(b.rotations[i].y == body.rotations[original].y);
    }
  }
  SECTION("tracks in order are written as they are") {
    CHECK(WalkToJson(back) == text);
    CHECK(back.tracks[0].keys.size() == walk.tracks[0].keys.size());
  }
}

TEST_CASE("WriteWalkJson writes a walk of many megabytes as WalkToJson gives it",
          "[export][walk_json]") {
  // The file is written as the text is built, a megabyte at a time: 60,000 keys (about 5.6 MB)
  // cross many of those pieces, each boundary within a key or between tracks.
  const Walk walk = test::LongCrowdWalk(10000);
  const std::string text = WalkToJson(walk);
  REQUIRE(text.size() > 5u << 20);
  const std::string path = test::ScratchPath("many_keys.json");
  std::string error;
  REQUIRE(WriteWalkJson(walk, path, &error) == Status::kOk);
  std::ifstream in(path, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::remove(path.c_str());
  CHECK(written.size() == text.size());
  CHECK(written == text);
  Walk back;
  REQUIRE(ParseWalkJson(written, path, &back, &error) == Status::kOk);
  CHECK(back.tracks.size() == walk.tracks.size());
  CHECK(back.tracks[0].keys.size() == walk.tracks[0].keys.size());
}

TEST_CASE("ParseWalkJson refuses zero and non-finite foot normals and body rotations",
          "[export][walk_json]") {
  const std::string head =
      R"({"format": "footfall-walk", "version": 1, "fps": 24, "tracks": [{"name": "body", )"
      R"("kind": "body", "keys": [{"frame": 1, "position": [0, 0, 0], "rotation": [0, 0, 0, 1]}]},)"
      "\n"
      R"({"name": "L", "kind": "foot", "keys": [)"
      R"({"frame": 1, "phase": "end", "position": [0, 0, 0], "normal": [0, 1, 0]},)"
      "\n";
  auto parse = [&head](const std::string& second_key, std::string* error) {
    Walk walk;
    return ParseWalkJson(head + second_key + "]}]}", "w.json", &walk, error);
  };
  std::string error;

  SECTION("a foot normal of zero length") {
    for (const char* normal : {"[0, 0, 0]", "[-0, 0, -0.0]", "[0.0, 0e10, 0]"}) {
      INFO(normal);
      error.clear();
      CHECK(parse(std::string(R"({"frame": 2, "phase": "start", "position": [0, 0, 0], )") +
                      R"("normal": )" + normal + "}",
                  &error) == Status::kParseError);
      CHECK(error ==
            "w.json: tracks[1].keys[1].normal: expected a non-zero normal [nx, ny, nz] (line 3)");
    }
  }
  SECTION("a foot normal with a number that is not finite") {
    // JSON has no NaN or Inf: 1e999, the one way to write one, is refused where it stands.
    CHECK(parse(R"({"frame": 2, "phase": "start", "position": [0, 0, 0], "normal": [0, 1e999, 0]})",
                &error) == Status::kParseError);
    CHECK(error ==
          "w.json:3:69: malformed JSON: number overflow parsing '1e999' (beyond the range of a "
          "double)");
  }
  SECTION("a tiny or huge foot normal is read as written") {
    for (const char* normal : {"[0, 1e-300, 0]", "[5e-324, 0, 0]", "[0, 0, -1e300]"}) {
      INFO(normal);
      CHECK(parse(std::string(R"({"frame": 2, "phase": "start", "position": [0, 0, 0], )") +
                      R"("normal": )" + normal + "}",
                  &error) == Status::kOk);
    }
  }
  SECTION("a foot key without a normal keeps the default up") {
    Walk walk;
    REQUIRE(ParseWalkJson(head + R"({"frame": 2, "phase": "start", "position": [0, 0, 0]}]}]})",
                          "w.json", &walk, &error) == Status::kOk);
    CHECK(walk.tracks[1].keys[1].normal == Vec3{0, 1, 0});
  }
  SECTION("body rotations: zero and not finite") {
    const std::string body_head =
        R"({"format": "footfall-walk", "version": 1, "fps": 24, "tracks": [{"name": "body", )"
        R"("kind": "body", "keys": [{"frame": 1, "position": [0, 0, 0], "rotation": )";
    Walk walk;
    CHECK(ParseWalkJson(body_head + "[0, 0, -0, 0]}]}]}", "w.json", &walk, &error) ==
          Status::kParseError);
    CHECK(error ==
          "w.json: tracks[0].keys[0].rotation: expected a non-zero quaternion "
          "[qx, qy, qz, qw] (line 1)");
    error.clear();
    CHECK(ParseWalkJson(body_head + "[0, 0, 0, -1e999]}]}]}", "w.json", &walk, &error) ==
          Status::kParseError);
    CHECK(error ==
          "w.json:1:165: malformed JSON: number overflow parsing '-1e999' (beyond the range of a "
          "double)");
  }
}

TEST_CASE("ParseWalkJson says on which line the value it refuses stands", "[export][walk_json]") {
  // A walk as `footfall generate` writes it: a line per key. (Errors named the value's path
  // alone: "tracks[1].keys[3].phase" left a file of thousands of lines to count.)
  const std::string text = WalkToJson(test::BipedWalk());
  auto line_of = [&text](const std::string& needle, size_t nth) {
    size_t at = text.find(needle);
    for (size_t i = 0; i < nth && at != std::string::npos; ++i) at = text.find(needle, at + 1);
    REQUIRE(at != std::string::npos);
    return 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + at, '\n'));
  };
  auto refuse = [](const std::string& bad) {
    Walk walk;
    std::string error;
    CHECK(ParseWalkJson(bad, "w.json", &walk, &error) == Status::kParseError);
    return error;
  };
  SECTION("a bad value: its own line") {
    // R's fourth key (tracks[1].keys[3]): its phase replaced.
    const size_t first_r_key = line_of("\"name\":\"R\"", 0) + 1;
    std::string bad = text;
    const size_t key = bad.find("\"phase\":\"", bad.find("\"name\":\"R\""));
    size_t at = key;
    for (int i = 0; i < 3; ++i) at = bad.find("\"phase\":\"", at + 1);
    bad.replace(bad.find('"', at + 8), 1, "\"jump");
    CHECK(refuse(bad) ==
          "w.json: tracks[1].keys[3].phase: expected \"start\", \"mid\" or \"end\" "
          "(line " +
              std::to_string(first_r_key + 3) + ")");
  }
  SECTION("a missing field: the line of the object without it") {
    std::string bad = text;
    const size_t at = bad.find(",\"phase\":\"mid\"");
    bad.erase(at, bad.find(',', at + 1) - at);
    CHECK(refuse(bad) ==
          "w.json: tracks[0].keys[1].phase: expected \"start\", \"mid\" or \"end\" "
          "(line 4)");
  }
  SECTION("nested values written over several lines") {
    const std::string pretty =
        "{\n  \"format\": \"footfall-walk\",\n  \"version\": 1,\n"
        "  \"fps\": 24,\n  \"tracks\": [\n    {\"name\": \"b\", \"kind\": "
        "\"body\",\n     \"keys\": [\n       {\"frame\": 1,\n"
        "        \"position\": [0, 0, 0]},\n       {\"frame\": 2,\n"
        "        \"position\": [0,\n 0,\n \"x\"]}]}]}";
    CHECK(refuse(pretty) ==
          "w.json: tracks[0].keys[1].position[2]: expected a finite number "
          "(line 13)");
    std::string fps = pretty;
    fps.replace(fps.find("24"), 2, "\"24\"");
    CHECK(refuse(fps) == "w.json: fps: expected a finite number (line 4)");
  }
  SECTION("field names written with escapes, and brackets in strings, do not mislead it") {
    const std::string odd =
        "{\"format\": \"footfall-walk\", \"version\": 1, \"fps\": 24, \"stopped\": \"a [b, {c\",\n"
        "\"tracks\": [{\"name\": \"x\\\"]\", \"kind\": \"foot\", \"keys\": [\n"
        "{\"fr\\u0061me\": 1, \"phase\": \"end\", \"position\": [0, 0, 0]},\n"
        "{\"frame\": 2, \"phase\": \"end\", \"position\": [0, 0, true]}]}]}";
    CHECK(refuse(odd) ==
          "w.json: tracks[0].keys[1].position[2]: expected a finite number "
          "(line 4)");
  }
}
