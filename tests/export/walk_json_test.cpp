// The walk JSON writer with walks built by hand: whatever the order of a track's keys, the text
// reads back, holding the keys the glTF and MEL exporters key.
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
