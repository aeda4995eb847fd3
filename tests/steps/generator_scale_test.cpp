// Scale: a character's lengths multiplied (ScaleCharacter, --scale, a request's "scale") walk the
// same walk on a terrain in other units.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "footfall/steps/character.h"
#include "footfall/steps/generate_request.h"
#include "footfall/steps/scene.h"
#include "generator_fixtures.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

namespace {

RawSamples Scaled(const RawSamples& samples, double scale) {
  RawSamples out = samples;
  for (Vec3& p : out.points) p = p * scale;
  return out;
}

// Whether b is a scaled by `scale`: the same tracks and keys (frames, phases, normals and
// rotations within `tolerance`), each position `scale` times a's within `tolerance` of b's
// size; both stopped or neither, at the same step.
void CheckScaled(const Walk& a, const Walk& b, double scale, double tolerance) {
  CHECK(a.stopped.empty() == b.stopped.empty());
  CHECK(a.stops.size() == b.stops.size());
  REQUIRE(a.tracks.size() == b.tracks.size());
  for (size_t t = 0; t < a.tracks.size(); ++t) {
    const WalkTrack &ta = a.tracks[t], &tb = b.tracks[t];
    INFO(ta.name);
    CHECK(ta.name == tb.name);
    CHECK(ta.kind == tb.kind);
    CHECK(tb.foot_length == Approx(ta.foot_length * scale).epsilon(1e-12));
    REQUIRE(ta.keys.size() == tb.keys.size());
    REQUIRE(ta.rotations.size() == tb.rotations.size());
    size_t off = 0;
    double worst = 0;
    for (size_t i = 0; i < ta.keys.size(); ++i) {
      const WalkKey &ka = ta.keys[i], &kb = tb.keys[i];
      if (ka.frame != kb.frame || ka.phase != kb.phase) ++off;
      const double size = std::max(1.0, Length(kb.position));
      worst = std::max({worst, Distance(ka.position * scale, kb.position) / size,
                        Distance(ka.normal, kb.normal)});
      if (i < ta.rotations.size()) {
        const Quat &qa = ta.rotations[i], &qb = tb.rotations[i];
        worst = std::max({worst, std::fabs(qa.x - qb.x), std::fabs(qa.y - qb.y),
                          std::fabs(qa.z - qb.z), std::fabs(qa.w - qb.w)});
      }
    }
    CHECK(off == 0);
    CHECK(worst <= tolerance);
  }
}

// Walks each shipped character 10 steps from the default start on `terrain_name` and on the
// terrain scaled by `scale`, scaled by `scale` too, and checks the walks with CheckScaled.
void CheckScaledWalks(const char* terrain_name, double scale, double tolerance) {
  const RawSamples samples = LoadShippedTerrain(terrain_name);
  Terrain small = LoadTerrain(samples, 0);
  Terrain large = LoadTerrain(Scaled(samples, scale), 0);
  for (const std::string& name : ShippedCharacters()) {
    INFO(terrain_name << ", " << name << ", scale " << scale);
    Character c = LoadShipped(name);
    if (name == "biped") c.foot_length = 0.22;
    Character s = c;
    std::string error;
    REQUIRE(ScaleCharacter(scale, &s, &error) == Status::kOk);
    GenerateOptions o;
    o.steps = 10;
    o.foot_rotations = true;
    const Walk a = Generate(small, c, o);
    const Walk b = Generate(large, s, o);
    CHECK(StepsDone(a) > 0);
    CheckScaled(a, b, scale, tolerance);
  }
}

}  // namespace

TEST_CASE("ScaleCharacter multiplies every length and nothing else", "[steps][character]") {
  for (const std::string& name : ShippedCharacters()) {
    INFO(name);
    Character c = LoadShipped(name);
    c.foot_length = 0.2;
    c.foot_width = 0.08;
    Character s = c;
    std::string error;
    REQUIRE(ScaleCharacter(100, &s, &error) == Status::kOk);
    REQUIRE(s.feet.size() == c.feet.size());
    for (size_t i = 0; i < c.feet.size(); ++i) {
      CHECK(s.feet[i].name == c.feet[i].name);
      CHECK(Distance(s.feet[i].rest, c.feet[i].rest * 100) == 0);
    }
    CHECK(s.step_length == c.step_length * 100);
    CHECK(s.step_height == c.step_height * 100);
    CHECK(s.body_height == c.body_height * 100);
    CHECK(s.max_rise == c.max_rise * 100);
    CHECK(s.reach == c.reach * 100);
    CHECK(s.foot_length == c.foot_length * 100);
    CHECK(s.foot_width == c.foot_width * 100);
    // Angles, frames and the gait stay.
    CHECK(s.frames_per_step == c.frames_per_step);
    CHECK(s.slope_threshold_deg == c.slope_threshold_deg);
    CHECK(s.slope_step_scale == c.slope_step_scale);
    CHECK(s.max_slope_deg == c.max_slope_deg);
    CHECK(s.max_turn_deg == c.max_turn_deg);
    CHECK(s.align_to_normal == c.align_to_normal);
    CHECK(s.gait == c.gait);
    CHECK(s.pairs == c.pairs);
    CHECK(s.name == c.name);
  }
}

TEST_CASE("ScaleCharacter refuses a scale out of its range or lengths out of a character's",
          "[steps][character]") {
  const Character c = LoadShipped("biped");
  struct Case {
    double scale;
    const char* expected;
  };
  const Case cases[] = {
      {0, "scale 0 is out of range [1e-06, 1e+06]"}, {-1, "scale -1 is out of range"},
      {2e6, "scale 2e+06 is out of range"},          {NAN, "scale nan is out of range"},
      {INFINITY, "scale inf is out of range"},
  };
  for (const Case& k : cases) {
    Character s = c;
    std::string error;
    CHECK(ScaleCharacter(k.scale, &s, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains(k.expected));
    CHECK(s.reach == c.reach);
  }
  // Lengths a character file may not give: beyond 1e9, or a positive one rounded to 0.
  Character big = c;
  big.reach = 2e3, big.step_length = 0.6;
  std::string error;
  CHECK(ScaleCharacter(1e6, &big, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("makes 'reach' 2e+09, out of a character's range (0, 1e+09]"));
  CHECK(big.reach == 2e3);
  Character tiny = c;
  tiny.step_height = 1e-320;
  CHECK(ScaleCharacter(1e-6, &tiny, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("makes 'step_height' 0"));
  CHECK(tiny.step_height == 1e-320);
}

TEST_CASE("A character scaled by s walks its walk scaled by s on its terrain scaled by s",
          "[steps][generator]") {
  SECTION("by powers of two, which scale every number exactly") {
    // The same walks but for rounding in what the generator sums and divides: no length in it
    // is absolute.
    const double scale = GENERATE(4.0, 0.25, 1024.0, 1.0 / 1024);
    for (const char* terrain : {"rocks", "stairs", "blocks"})
      CheckScaledWalks(terrain, scale, 1e-9);
  }
  SECTION("from metres to centimetres") {
    // Rounded coordinates: on a lattice, footholds the same distance from a target may be
    // chosen the other way round. The rocks have no such ties.
    CheckScaledWalks("rocks", 100, 1e-6);
  }
}

TEST_CASE("A request's and a scene's scale multiply their character's lengths",
          "[steps][character]") {
  const std::string character = "\"character_file\": \"" + std::string(FOOTFALL_SOURCE_DIR) +
                                "/data/characters/quadruped.json\"";
  Character plain, scaled;
  GenerateOptions o;
  std::string error;
  REQUIRE(ParseGenerateRequest("{" + character + "}", &plain, &o, &error) == Status::kOk);
  REQUIRE(ParseGenerateRequest("{" + character + ", \"scale\": 100}", &scaled, &o, &error) ==
          Status::kOk);
  CHECK(scaled.reach == plain.reach * 100);
  CHECK(scaled.step_length == plain.step_length * 100);
  CHECK(ParseGenerateRequest("{" + character + ", \"scale\": 0}", &scaled, &o, &error) ==
        Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("request: 'scale': scale 0 is out of range"));
  CHECK(ParseGenerateRequest("{" + character + ", \"scale\": \"2\"}", &scaled, &o, &error) ==
        Status::kParseError);
  CHECK_THAT(error, Catch::Contains("request: 'scale': expected a finite number"));
  // A scene's characters each at their own scale; a bad one named with its line.
  const std::string head = "{\"format\": \"footfall-scene\", \"version\": 1, \"characters\": [\n";
  std::vector<SceneCharacter> scene;
  REQUIRE(ParseScene(head + "{" + character + "},\n{" + character + ", \"scale\": 0.5}]}",
                     "scene.json", ".", &scene, &error) == Status::kOk);
  REQUIRE(scene.size() == 2);
  CHECK(scene[1].character.reach == scene[0].character.reach * 0.5);
  CHECK(scene[0].character.reach == plain.reach);
  CHECK(ParseScene(head + "{" + character + "},\n{" + character + ", \"scale\": -2}]}",
                   "scene.json", ".", &scene, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("(line 3)"));
  CHECK_THAT(error, Catch::Contains("characters[1]: 'scale': scale -2 is out of range"));
}

TEST_CASE("A terrain in other units than the character is said, with the scale that fits",
          "[steps][generator]") {
  const RawSamples rocks = LoadShippedTerrain("rocks");
  Terrain metres = LoadTerrain(rocks, 0);
  Terrain centimetres = LoadTerrain(Scaled(rocks, 100), 0);
  const Character biped = LoadShipped("biped");
  GenerateOptions o;
  o.steps = 4;
  // In the same units: no note.
  CHECK(Generate(metres, biped, o).notes.empty());
  // A character in metres on a terrain in centimetres: its samples lie many steps apart.
  const Walk coarse = Generate(centimetres, biped, o);
  REQUIRE(coarse.notes.size() == 1);
  CHECK_THAT(coarse.notes[0], Catch::StartsWith("the terrain's samples lie about 6.75 apart, "
                                                "more than 4 of this character's steps"));
  CHECK_THAT(coarse.notes[0], Catch::EndsWith("(--scale; 100 from metres to centimetres)"));
  // Scaled, it walks with no note.
  Character scaled = biped;
  std::string error;
  REQUIRE(ScaleCharacter(100, &scaled, &error) == Status::kOk);
  const Walk fitted = Generate(centimetres, scaled, o);
  CHECK(fitted.notes.empty());
  CHECK(fitted.stopped.empty());
  // A character in centimetres on a terrain in metres: the terrain is smaller than its reach.
  // A request names its own field.
  GenerateOptions request = o;
  request.names.scale = "request: 'scale'";
  const Walk large = Generate(metres, scaled, request);
  REQUIRE(large.notes.size() == 1);
  CHECK_THAT(large.notes[0],
             Catch::StartsWith("the terrain is 7.99 across, less than this character's reach 120"));
  CHECK_THAT(large.notes[0],
             Catch::EndsWith("(request: 'scale'; 0.01 from centimetres to metres)"));
}
