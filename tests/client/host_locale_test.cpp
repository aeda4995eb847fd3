// The C ABI and the C++ readers in a host program that set its locale from the user's (Maya
// follows its UI language): requests, character, walk and terrain files read as in the "C"
// locale, and the host's locale is as it was after each call.
#include <clocale>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/client/footfall_c.h"
#include "footfall/steps/character.h"
#include "footfall/steps/walk_json.h"

namespace {

// Sets the C locale to the first of `names` that is installed, for its lifetime; FAILs naming
// them when none is (scripts/install-deps.sh test generates them).
class HostLocale {
 public:
  explicit HostLocale(std::initializer_list<const char*> names) {
    for (const char* name : names)
      if (std::setlocale(LC_ALL, name)) {
        name_ = name;
        return;
      }
    FAIL("none of the locales is installed (" << *names.begin()
                                              << "...): run scripts/install-deps.sh test");
  }
  ~HostLocale() { std::setlocale(LC_ALL, "C"); }
  HostLocale(const HostLocale&) = delete;
  HostLocale& operator=(const HostLocale&) = delete;
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

// The walk JSON ffc_generate returns for `request` on the bundled hills, in the current locale.
std::string Generate(const std::string& request) {
  ffc_session* s = ffc_open_embedded();
  REQUIRE(s);
  uint32_t hills = 0;
  REQUIRE(ffc_load_file(s, FOOTFALL_SOURCE_DIR "/data/terrain/hills.pts", 0, &hills) == FF_C_OK);
  char* walk = nullptr;
  const int32_t status = ffc_generate(s, hills, request.c_str(), &walk);
  INFO(ffc_last_error(s));
  REQUIRE(status == FF_C_OK);
  const std::string text = walk;
  ffc_free_string(walk);
  ffc_close(s);
  return text;
}

// The samples ffc_load_file reads from `path`, in the current locale; -1 when it refuses it.
long long SampleCount(const std::string& path) {
  ffc_session* s = ffc_open_embedded();
  REQUIRE(s);
  uint32_t terrain = 0;
  long long count = -1;
  if (ffc_load_file(s, path.c_str(), 0, &terrain) == FF_C_OK) {
    uint64_t samples = 0;
    double bounds[6];
    REQUIRE(ffc_info(s, terrain, &samples, bounds) == FF_C_OK);
    count = static_cast<long long>(samples);
  } else {
    WARN(ffc_last_error(s));
  }
  ffc_close(s);
  return count;
}

}  // namespace

TEST_CASE("ffc_generate reads a request's numbers whatever the host's decimal point",
          "[client][locale]") {
  // Pashto's decimal point is two bytes (U+066B): the JSON reader, which swaps '.' for the
  // locale's point, read 10.75 as 10, and every character file's rests collided.
  const std::string request = "{\"character_file\": \"" FOOTFALL_SOURCE_DIR
                              "/data/characters/biped.json\", \"start\": [10.75, 0, 10.75], "
                              "\"heading\": [0.6, 0, 0.8], \"steps\": 3}";
  const std::string in_c = Generate(request);
  for (auto names : {std::initializer_list<const char*>{"ps_AF.UTF-8", "ps_AF.utf8"},
                     std::initializer_list<const char*>{"de_DE.UTF-8", "de_DE.utf8"}}) {
    const HostLocale host(names);
    INFO("host locale " << host.name());
    const std::string point = std::localeconv()->decimal_point;
    CHECK(point != ".");  // the locale is one that differs from C's
    CHECK(Generate(request) == in_c);
    CHECK(std::string(std::localeconv()->decimal_point) == point);  // the host's, after
  }
}

TEST_CASE("ffc_load_file reads a height map's headers whatever the host's letter case rules",
          "[client][locale]") {
  // In a Turkish locale 'I' does not lower to 'i': CELLSIZE and NODATA_VALUE were unknown.
  const std::string path = "c_abi_locale_test.asc";
  {
    std::ofstream asc(path);
    asc << "NCOLS 3\nNROWS 2\nXLLCORNER 0\nYLLCORNER 0\nCELLSIZE 1.5\nNODATA_VALUE -9999\n"
           "1 2 3\n4 5 -9999\n";
  }
  const long long in_c = SampleCount(path);
  REQUIRE(in_c > 0);
  {
    const HostLocale host({"tr_TR.UTF-8", "tr_TR.utf8"});
    CHECK(SampleCount(path) == in_c);
  }
  std::remove(path.c_str());
}

TEST_CASE("the C++ readers read character and walk files whatever the host's decimal point",
          "[client][locale]") {
  // LoadCharacter refused biped.json (its rests collided as whole numbers), and ReadWalkJson
  // refused a walk the command line wrote.
  const std::string biped = FOOTFALL_SOURCE_DIR "/data/characters/biped.json";
  footfall::Character in_c;
  std::string error;
  REQUIRE(footfall::LoadCharacter(biped, &in_c, &error) == footfall::Status::kOk);
  const std::string walk_text = Generate("{\"character_file\": \"" + biped + "\", \"steps\": 3}");
  footfall::Walk walk_in_c;
  REQUIRE(footfall::ParseWalkJson(walk_text, "walk.json", &walk_in_c, &error) ==
          footfall::Status::kOk);
  const HostLocale host({"ps_AF.UTF-8", "ps_AF.utf8"});
  footfall::Character character;
  INFO(error);
  REQUIRE(footfall::LoadCharacter(biped, &character, &error) == footfall::Status::kOk);
  CHECK(character.step_length == in_c.step_length);
  REQUIRE(character.feet.size() == in_c.feet.size());
  for (size_t i = 0; i < character.feet.size(); ++i) {
    CHECK(character.feet[i].rest.x == in_c.feet[i].rest.x);
    CHECK(character.feet[i].rest.z == in_c.feet[i].rest.z);
  }
  footfall::Walk walk;
  REQUIRE(footfall::ParseWalkJson(walk_text, "walk.json", &walk, &error) == footfall::Status::kOk);
  CHECK(footfall::WalkToJson(walk) == footfall::WalkToJson(walk_in_c));
  CHECK(std::string(std::localeconv()->decimal_point) != ".");  // the host's, after
}
