// Files written in a host process that set a decimal-comma locale (Maya and Blender embed the
// library and may set LC_NUMERIC, or the C++ global locale, from the user's settings): MEL, walk
// JSON, glTF and point files hold the same bytes as in the "C" locale.
#include <clocale>
#include <cstdio>
#include <fstream>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/export/gltf_writer.h"
#include "footfall/export/mel_writer.h"
#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/walk_json.h"
#include "footfall/terrain/point_file.h"
#include "walk_fixtures.h"

using namespace footfall;

namespace {

// Locales whose decimal separator is a comma; scripts/install-deps.sh test generates the first.
const char* const kCommaLocales[] = {"de_DE.UTF-8", "de_DE.utf8",  "fr_FR.UTF-8", "fr_FR.utf8",
                                     "nl_NL.UTF-8", "es_ES.UTF-8", "it_IT.UTF-8", "pt_BR.UTF-8",
                                     "ru_RU.UTF-8", "de_DE",       "fr_FR"};

// The first installed locale of kCommaLocales whose C decimal point is ',', or "". Leaves the C
// locale as "C".
std::string FindCommaLocale() {
  std::string found;
  for (const char* name : kCommaLocales) {
    if (std::setlocale(LC_ALL, name) && std::string(std::localeconv()->decimal_point) == ",") {
      found = name;
      break;
    }
  }
  std::setlocale(LC_ALL, "C");
  return found;
}

// Sets the C locale and the C++ global locale to `name` for its lifetime, then back to "C".
class LocaleScope {
 public:
  explicit LocaleScope(const std::string& name) {
    std::locale::global(std::locale(name));  // also sets the C locale (LC_ALL)
  }
  ~LocaleScope() {
    std::locale::global(std::locale::classic());
    std::setlocale(LC_ALL, "C");
  }
  LocaleScope(const LocaleScope&) = delete;
  LocaleScope& operator=(const LocaleScope&) = delete;
};

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A biped walk with numbers of every kind: fractions, tiny and huge values, whole numbers
// beyond a 32-bit int, a fractional fps.
Walk NumbersWalk() {
  Walk walk = test::BipedWalk();
  walk.fps = 23.976;
  WalkTrack& left = walk.tracks[0];
  left.keys[0].frame = 1.0000004;
  left.keys[0].position = {1e-9, 123456.789012345, -2.5e-5};
  left.keys[1].position = {1e15, 0.1 + 0.2, -0.0};
  left.keys[2].position = {-2147483648.0, 2147483647.5, 2.0 / 3.0};
  left.keys[1].normal = {0.6, 0.8, 0};
  walk.tracks[2].keys[1].position = {-1e-12, 1e12, 1234.5};
  return walk;
}

// Every file format written for `walk` (and a few samples), as name -> bytes.
std::vector<std::pair<std::string, std::string>> WriteAll(const Walk& walk,
                                                          const std::string& tag) {
  std::vector<std::pair<std::string, std::string>> files;
  std::string error;
  const std::string mel = test::ScratchPath(tag + ".mel");
  REQUIRE(WriteMel(walk, mel, &error) == Status::kOk);
  const std::string json = test::ScratchPath(tag + ".json");
  REQUIRE(WriteWalkJson(walk, json, &error) == Status::kOk);
  const std::string gltf = test::ScratchPath(tag + ".gltf");
  REQUIRE(WriteGltf(walk, gltf, &error) == Status::kOk);
  GltfOptions binary;
  binary.binary = true;
  const std::string glb = test::ScratchPath(tag + ".glb");
  REQUIRE(WriteGltf(walk, glb, binary, &error) == Status::kOk);
  RawSamples samples;
  samples.push_back({0.5, -1234567.25, 1e-7}, {0.6, 0.8, 0});
  samples.push_back({3e14, 2.0 / 3.0, -0.1}, {0, 1, 0});
  const std::string pts = test::ScratchPath(tag + ".pts");
  REQUIRE(WritePointFile(pts, samples, &error) == Status::kOk);
  for (const std::string& path : {mel, json, gltf, glb, pts}) {
    files.emplace_back(path.substr(path.rfind('.')), ReadBytes(path));
    std::remove(path.c_str());
  }
  return files;
}

// A biped walking 12 steps along +Z across a 2 x 3 m plateau (5 cm samples) that ends in a
// cliff: it stops at the edge, after 1,000.5 frames' worth of start frame.
Walk CliffWalk() {
  RawSamples ground;
  for (int i = 0; i <= 40; ++i)
    for (int k = 0; k <= 60; ++k) ground.push_back({-1 + 0.05 * i, 0.125, 0.05 * k}, {0, 1, 0});
  const char* const biped = R"({"format": "footfall-character", "version": 1, "name": "biped",
    "feet": [{"name": "L", "rest": [0.12, 0, 0]}, {"name": "R", "rest": [-0.12, 0, 0]}],
    "gait": [["L"], ["R"]], "pairs": [["L", "R"]], "step_length": 0.7, "step_height": 0.15,
    "body_height": 0.95, "frames_per_step": 12, "align_to_normal": false,
    "slope_threshold_deg": 15, "slope_step_scale": 0.6, "max_slope_deg": 45, "max_rise": 0.4,
    "reach": 1.2, "max_turn_deg": 30})";
  Character character;
  std::string error;
  if (ParseCharacter(biped, "biped", &character, &error) != Status::kOk) FAIL(error);
  auto session = MakeEmbeddedSession(1);
  TerrainHandle terrain = 0;
  REQUIRE(session->LoadSamples(ground, "plateau", &terrain) == Status::kOk);
  GenerateOptions options;
  options.has_start = true;
  options.start = {0, 0.125, 0.5};
  options.steps = 12;
  options.start_frame = 1000.5;
  Walk walk;
  REQUIRE(GenerateWalk(*session, terrain, character, options, &walk, &error) == Status::kOk);
  return walk;
}

}  // namespace

TEST_CASE("A walk's stop reason reads the same in a decimal-comma locale", "[export][locale]") {
  const std::string comma = FindCommaLocale();
  if (comma.empty()) {
    FAIL(
        "no decimal-comma locale is installed (tried de_DE.UTF-8, fr_FR.UTF-8 and others): "
        "run scripts/install-deps.sh test, which generates de_DE.UTF-8");
  }
  const Walk in_c = CliffWalk();
  REQUIRE_FALSE(in_c.stopped.empty());
  INFO("stopped: " << in_c.stopped);
  // Its position, with decimals.
  CHECK_THAT(in_c.stopped, Catch::Contains("."));
  Walk in_comma;
  {
    LocaleScope scope(comma);
    std::ostringstream stream;
    stream << 1.5 << ' ' << 1000;
    REQUIRE(stream.str() == "1,5 1.000");
    in_comma = CliffWalk();
  }
  CHECK(in_comma.stopped == in_c.stopped);
  CHECK(in_comma.stops == in_c.stops);
}

TEST_CASE("Walk exports and point files are the same bytes in a decimal-comma locale",
          "[export][locale]") {
  const std::string comma = FindCommaLocale();
  if (comma.empty()) {
    FAIL(
        "no decimal-comma locale is installed (tried de_DE.UTF-8, fr_FR.UTF-8 and others): "
        "run scripts/install-deps.sh test, which generates de_DE.UTF-8");
  }
  INFO("locale " << comma);
  for (const Walk& walk : {NumbersWalk(), test::CrowdWalk(), test::FarWalk()}) {
    const auto in_c = WriteAll(walk, "locale_c");
    std::vector<std::pair<std::string, std::string>> in_comma;
    {
      LocaleScope scope(comma);
      // The locale is in force for printf and for C++ streams alike.
      char text[16];
      std::snprintf(text, sizeof text, "%.1f", 1.5);
      REQUIRE(std::string(text) == "1,5");
      std::ostringstream stream;
      stream << 1.5;
      REQUIRE(stream.str() == "1,5");
      in_comma = WriteAll(walk, "locale_comma");
    }
    REQUIRE(in_c.size() == in_comma.size());
    for (size_t i = 0; i < in_c.size(); ++i) {
      INFO("file " << in_c[i].first);
      CHECK(in_comma[i].second == in_c[i].second);
    }
  }
}

TEST_CASE("WriteMel writes points in a decimal-comma locale", "[export][mel][locale]") {
  const std::string comma = FindCommaLocale();
  if (comma.empty()) {
    FAIL(
        "no decimal-comma locale is installed (tried de_DE.UTF-8, fr_FR.UTF-8 and others): "
        "run scripts/install-deps.sh test, which generates de_DE.UTF-8");
  }
  std::string text;
  {
    LocaleScope scope(comma);
    const std::string path = test::ScratchPath("comma.mel");
    std::string error;
    REQUIRE(WriteMel(NumbersWalk(), path, &error) == Status::kOk);
    text = ReadBytes(path);
    std::remove(path.c_str());
  }
  CHECK_THAT(text, Catch::Contains("// footfall walk: 3 tracks at 23.976 fps."));
  CHECK_THAT(text, Catch::Contains("currentUnit -time \"23.976fps\";"));
  CHECK_THAT(text, Catch::Contains("setKeyframe -t 1.0000004 -at translateX -v 0.000000001 "));
  CHECK_THAT(text, Catch::Contains("-at translateY -v 123456.789012345 "));
  CHECK_THAT(text, Catch::Contains("-at translateX -v 1000000000000000.0 "));
  CHECK_THAT(text, Catch::Contains("-at translateY -v 0.30000000000000004 "));
  CHECK_THAT(text, Catch::Contains("-at translateX -v -2147483648.0 "));
  CHECK_THAT(text, Catch::Contains("-at translateY -v 2147483647.5 "));
  CHECK_THAT(text, Catch::Contains("-at translateZ -v 0.6666666666666666 "));
  CHECK_THAT(text, Catch::Contains("-at translateY -v 1000000000000.0 "));
  CHECK_THAT(text, !Catch::Contains(","));
}
