// The walk JSON writer with walks built by hand: whatever the order of a track's keys, the text
// reads back, holding the keys the glTF and MEL exporters key.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <utility>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

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

TEST_CASE("EmitWalkJson gives the same text on any number of threads", "[export][walk_json]") {
  // Runs of a few thousand keys are formatted on several threads and handed over in order:
  // tracks cut into several runs, a track whose keys are written reordered, an empty track.
  Walk walk = test::LongCrowdWalk(10000);
  std::swap(walk.tracks[1].keys[5], walk.tracks[1].keys[9000]);
  walk.tracks.push_back(WalkTrack{});
  walk.tracks.back().name = "empty";
  auto emit = [&walk](int threads, size_t* pieces) {
    std::string text;
    *pieces = 0;
    CHECK(EmitWalkJson(
        walk,
        [&](std::string_view piece) {
          text += piece;
          ++*pieces;
          return true;
        },
        threads));
    return text;
  };
  size_t pieces = 0;
  const std::string one = emit(1, &pieces);
  CHECK(pieces > 8);
  Walk back;
  std::string error;
  REQUIRE(ParseWalkJson(one, "w.json", &back, &error) == Status::kOk);
  CHECK(back.tracks.size() == walk.tracks.size());
  CHECK(back.tracks[1].keys[5].frame < back.tracks[1].keys[6].frame);
  for (const int threads : {2, 3, 0}) {
    INFO(threads << " threads");
    size_t more = 0;
    CHECK(emit(threads, &more) == one);
    CHECK(more == pieces);
  }
  // A sink that refuses stops the text at once, whatever the threads.
  for (const int threads : {1, 3}) {
    size_t calls = 0;
    CHECK_FALSE(EmitWalkJson(
        walk, [&calls](std::string_view) { return ++calls < 3; }, threads));
    CHECK(calls == 3);
  }
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

namespace {

// The message ParseWalkJson refuses `text` with once its first `replaced` is replaced by `by`.
std::string RefusedEdit(const std::string& text, const std::string& replaced,
                        const std::string& by) {
  std::string bad = text;
  const size_t at = bad.find(replaced);
  REQUIRE(at != std::string::npos);
  bad.replace(at, replaced.size(), by);
  Walk w;
  std::string message;
  CHECK(ParseWalkJson(bad, "w.json", &w, &message) == Status::kParseError);
  return message;
}

}  // namespace

TEST_CASE("A foot track's foot_width is written after its foot_length, read back and checked",
          "[export][walk_json]") {
  Walk walk = test::BipedWalk();  // tracks L, R, body
  walk.tracks[0].foot_length = 0.22, walk.tracks[0].foot_width = 0.1;
  const std::string text = WalkToJson(walk);
  CHECK(text.find("\"name\":\"L\",\"kind\":\"foot\",\"foot_length\":0.22,\"foot_width\":0.1,"
                  "\"keys\"") != std::string::npos);
  CHECK(text.find("foot_width", text.find("\"name\":\"R\"")) == std::string::npos);
  Walk back, whole;
  std::string error;
  REQUIRE(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  CHECK(back.tracks[0].foot_width == 0.1);
  CHECK(back.tracks[1].foot_width == 0);
  CHECK(WalkToJson(back) == text);
  REQUIRE(detail::ParseWalkJsonWhole(text, "w.json", &whole, &error) == Status::kOk);
  CHECK(whole.tracks[0].foot_width == 0.1);
  const std::string w = "\"foot_width\":0.1";
  CHECK(RefusedEdit(text, w, "\"foot_width\":-0.1") ==
        "w.json: tracks[0].foot_width: expected a length in [0, 1e9] (the character's "
        "foot_width) (line 2)");
  CHECK(RefusedEdit(text, w, "\"foot_width\":null") ==
        "w.json: tracks[0].foot_width: expected a finite number (line 2)");
  CHECK(RefusedEdit(text, "\"kind\":\"body\"", "\"kind\":\"body\",\"foot_width\":0.2")
            .find("tracks[2].foot_width: only a foot track has a foot_width") != std::string::npos);
}

TEST_CASE("A foot track's foot_length is written, read back and checked", "[export][walk_json]") {
  Walk walk = test::BipedWalk();  // tracks L, R, body
  walk.tracks[0].foot_length = 0.22;
  walk.tracks[1].foot_length = 1.0 / 3;  // the shortest text that reads back as the double
  const std::string text = WalkToJson(walk);
  CHECK(text.find("\"name\":\"L\",\"kind\":\"foot\",\"foot_length\":0.22,\"keys\"") !=
        std::string::npos);
  Walk back;
  std::string error;
  REQUIRE(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  CHECK(back.tracks[0].foot_length == 0.22);
  CHECK(back.tracks[1].foot_length == 1.0 / 3);
  CHECK(back.tracks[2].foot_length == 0);
  CHECK(WalkToJson(back) == text);

  // Point feet (0) write none, as walks did before.
  walk.tracks[0].foot_length = 0;
  const std::string point = WalkToJson(walk);
  CHECK(point.find("\"name\":\"L\",\"kind\":\"foot\",\"keys\"") != std::string::npos);
  CHECK(point.find("foot_length", point.find("\"name\":\"R\"")) != std::string::npos);
  CHECK(point.find("foot_length") > point.find("\"name\":\"R\""));

  const std::string l = "\"foot_length\":0.22";
  CHECK(RefusedEdit(text, l, "\"foot_length\":-0.1") ==
        "w.json: tracks[0].foot_length: expected a length in [0, 1e9] (the character's "
        "foot_length) (line 2)");
  CHECK(RefusedEdit(text, l, "\"foot_length\":2e9").find("expected a length in [0, 1e9]") !=
        std::string::npos);
  CHECK(RefusedEdit(text, l, "\"foot_length\":\"long\"") ==
        "w.json: tracks[0].foot_length: expected a finite number (line 2)");
  CHECK(RefusedEdit(text, "\"kind\":\"body\"", "\"kind\":\"body\",\"foot_length\":0.2")
            .find("tracks[2].foot_length: only a foot track has a foot_length") !=
        std::string::npos);
  // Read the same as the keys are parsed and as a whole document, and in another tool's
  // order of fields (sorted: foot_length and keys before kind).
  Walk whole;
  REQUIRE(detail::ParseWalkJsonWhole(text, "w.json", &whole, &error) == Status::kOk);
  CHECK(whole.tracks[0].foot_length == 0.22);
  const std::string sorted = nlohmann::json::parse(text).dump(2);
  REQUIRE(sorted.find("\"foot_length\"") < sorted.find("\"kind\""));
  Walk resorted;
  REQUIRE(ParseWalkJson(sorted, "w.json", &resorted, &error) == Status::kOk);
  CHECK(resorted.tracks[0].foot_length == 0.22);
  CHECK(resorted.tracks[1].foot_length == 1.0 / 3);
  CHECK(WalkToJson(resorted) == text);
}

TEST_CASE("A walk's unit is written, read back and checked", "[export][walk_json]") {
  Walk walk = test::BipedWalk();
  const std::string without = WalkToJson(walk);
  CHECK(without.find("unit") == std::string::npos);  // as walks were before
  walk.unit = "cm";
  const std::string text = WalkToJson(walk);
  CHECK(text.rfind("{\"format\":\"footfall-walk\",\"version\":1,\"fps\":24,\"unit\":\"cm\",", 0) ==
        0);
  Walk back;
  std::string error;
  REQUIRE(ParseWalkJson(text, "w.json", &back, &error) == Status::kOk);
  CHECK(back.unit == "cm");
  CHECK(WalkToJson(back) == text);
  Walk whole;
  REQUIRE(detail::ParseWalkJsonWhole(text, "w.json", &whole, &error) == Status::kOk);
  CHECK(whole.unit == "cm");
  REQUIRE(ParseWalkJson(without, "w.json", &back, &error) == Status::kOk);
  CHECK(back.unit.empty());
  for (const char* bad : {"\"furlong\"", "\"CM\"", "100", "\"\""}) {
    INFO(bad);
    std::string refused = text;
    refused.replace(refused.find("\"cm\""), 4, bad);
    Walk w;
    CHECK(ParseWalkJson(refused, "w.json", &w, &error) == Status::kParseError);
    CHECK(error == "w.json: unit: expected one of mm, cm, m, km, in, ft, yd or mi (line 1)");
  }
}

namespace {

// The first difference between two walks read from JSON ("" when they are the same).
std::string WalkDifference(const Walk& a, const Walk& b) {
  if (a.fps != b.fps || a.stopped != b.stopped) return "fps or stopped";
  if (a.tracks.size() != b.tracks.size()) return "track count";
  for (size_t t = 0; t < a.tracks.size(); ++t) {
    const WalkTrack& x = a.tracks[t];
    const WalkTrack& y = b.tracks[t];
    const std::string at = "track " + std::to_string(t) + ": ";
    if (x.name != y.name || x.character != y.character || x.kind != y.kind ||
        x.foot_length != y.foot_length || x.foot_width != y.foot_width)
      return at + "name, character, kind, foot_length or foot_width";
    if (x.keys.size() != y.keys.size() || x.rotations.size() != y.rotations.size())
      return at + "key count";
    for (size_t k = 0; k < x.keys.size(); ++k) {
      const WalkKey& p = x.keys[k];
      const WalkKey& q = y.keys[k];
      if (p.frame != q.frame || p.position != q.position || p.normal != q.normal ||
          p.phase != q.phase)
        return at + "key " + std::to_string(k);
    }
    for (size_t k = 0; k < x.rotations.size(); ++k) {
      const Quat& p = x.rotations[k];
      const Quat& q = y.rotations[k];
      if (p.x != q.x || p.y != q.y || p.z != q.z || p.w != q.w)
        return at + "rotation " + std::to_string(k);
    }
  }
  return "";
}

struct Reading {
  Status status;
  std::string error;
  Walk walk;
};

Reading Streamed(const std::string& text) {
  Reading r;
  r.status = ParseWalkJson(text, "w.json", &r.walk, &r.error);
  return r;
}

Reading Whole(const std::string& text) {
  Reading r;
  r.status = detail::ParseWalkJsonWhole(text, "w.json", &r.walk, &r.error);
  return r;
}

// `text` read as its keys are parsed and read as a whole document: the same status, message
// and walk. Returns the streamed reading.
Reading ReadBothWays(const std::string& text) {
  Reading s = Streamed(text);
  const Reading w = Whole(text);
  CHECK(s.status == w.status);
  CHECK(s.error == w.error);
  if (s.status == Status::kOk && w.status == Status::kOk)
    CHECK(WalkDifference(s.walk, w.walk) == "");
  return s;
}

}  // namespace

TEST_CASE("ParseWalkJson reads keys as they are parsed as the whole document reads them",
          "[export][walk_json]") {
  // Keys are taken from the parser as each key object ends and left out of the document (a
  // crowd's walk of millions of keys stood whole in memory at about five times its text); the
  // result and every message must stay those of reading the whole document.
  const Walk walk = test::LongCrowdWalk(500);
  const std::string text = WalkToJson(walk);

  SECTION("as footfall writes it: every track's kind before its keys") {
    const Reading r = ReadBothWays(text);
    REQUIRE(r.status == Status::kOk);
    CHECK(WalkDifference(r.walk, walk) == "");
  }
  SECTION("kind after keys (written by another tool, in sorted order): keys kept, then read") {
    const std::string sorted = nlohmann::json::parse(text).dump(2);
    REQUIRE(sorted.find("\"keys\"") < sorted.find("\"kind\""));
    const Reading r = ReadBothWays(sorted);
    REQUIRE(r.status == Status::kOk);
    CHECK(WalkDifference(r.walk, walk) == "");
  }
  SECTION("tracks of both orders in one file") {
    nlohmann::json j = nlohmann::json::parse(text);
    // Track 1 rewritten with its kind last: the others stay as written.
    const std::string kind = "\"kind\":" + j["tracks"][1]["kind"].dump();
    std::string mixed = text;
    const size_t track1 = mixed.find("\"name\":\"R1\"");
    REQUIRE(track1 != std::string::npos);
    const size_t at = mixed.find(kind, track1);
    REQUIRE(at != std::string::npos);
    mixed.erase(at, kind.size() + 1);            // with its comma
    const size_t close = mixed.find("}]}", at);  // its last key, keys and track end
    mixed.insert(close + 2, "," + kind);
    REQUIRE(mixed.find(kind, track1) > mixed.find("\"keys\"", track1));
    const Reading r = ReadBothWays(mixed);
    INFO(r.error);
    REQUIRE(r.status == Status::kOk);
    CHECK(WalkDifference(r.walk, walk) == "");
  }
  SECTION("a refused key: the first error in reading order, as before") {
    // A bad key in the last track, and a bad fps written after the tracks: the fps is read
    // first, as the whole document is.
    std::string bad = text;
    const size_t last = bad.rfind("\"phase\":\"");
    REQUIRE(last != std::string::npos);
    bad.replace(last + 9, 0, "x");
    const Reading key_only = ReadBothWays(bad);
    CHECK(key_only.status == Status::kParseError);
    CHECK(key_only.error.find(".phase: expected \"start\", \"mid\" or \"end\"") !=
          std::string::npos);
    const size_t fps = bad.find("\"fps\":30,");
    REQUIRE(fps != std::string::npos);
    bad.erase(fps, 9);
    bad.insert(bad.rfind('}'), ",\"fps\":-1");
    const Reading both = ReadBothWays(bad);
    CHECK(both.status == Status::kParseError);
    CHECK(both.error.rfind("w.json: fps: expected a positive number (line ", 0) == 0);
  }
  SECTION("a key refused in a track whose name is refused: the name, as before") {
    std::string bad = text;
    const size_t name = bad.find("\"name\":\"L1\"");
    REQUIRE(name != std::string::npos);
    bad.replace(name + 8, 2, "\\u0007");
    const size_t frame = bad.find("\"frame\":", bad.find("\"keys\"", name));
    bad.replace(frame + 8, 0, "\"");
    bad.replace(bad.find(',', frame), 0, "\"");
    const Reading r = ReadBothWays(bad);
    CHECK(r.status == Status::kParseError);
    CHECK(r.error.find("tracks[0].name: expected a name without control characters") !=
          std::string::npos);
  }
  SECTION("damaged at random: the same status, message and walk both ways") {
    const std::string small = WalkToJson(test::CrowdWalk());
    std::mt19937 rng(7);
    const std::string pieces[] = {
        "{",           "}", "[",     "]",    ",",          ":", "\"kind\":\"body\"",
        "\"keys\":[]", "1", "\"x\"", "null", "\"frame\":2"};
    size_t ok = 0;
    for (int i = 0; i < 3000; ++i) {
      std::string damaged = small;
      const int edits = 1 + static_cast<int>(rng() % 3);
      for (int e = 0; e < edits; ++e) {
        const size_t at = rng() % damaged.size();
        switch (rng() % 4) {
          case 0:
            damaged.erase(at, 1 + rng() % 12);
            break;
          case 1:
            damaged.insert(at, pieces[rng() % std::size(pieces)]);
            break;
          case 2:
            damaged[at] = "0123456789-.e\"{}[],:"[rng() % 20];
            break;
          default: {  // a stretch moved elsewhere
            const size_t n = std::min<size_t>(1 + rng() % 40, damaged.size() - at);
            const std::string cut = damaged.substr(at, n);
            damaged.erase(at, n);
            damaged.insert(rng() % (damaged.size() + 1), cut);
          }
        }
      }
      INFO("case " << i << ": " << damaged);
      ok += ReadBothWays(damaged).status == Status::kOk;
    }
    // Some damage leaves valid walks (a digit changed), most does not: both kinds were read.
    CHECK(ok > 30);
    CHECK(ok < 2900);
  }
}
