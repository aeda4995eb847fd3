// Terrain handles: never 0, never one still loaded, also once the counter wraps past 2^32 - 1.
#include <set>

#include <catch2/catch.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "handle_counter.h"

using namespace footfall;

TEST_CASE("HandleCounter wraps past the top skipping 0 and handles in use", "[client]") {
  HandleCounter counter(0xFFFFFFFEu);
  const std::set<TerrainHandle> live = {0xFFFFFFFFu, 1, 2, 4};
  auto in_use = [&live](TerrainHandle h) { return live.count(h) != 0; };
  CHECK(counter.Next(in_use) == 0xFFFFFFFEu);
  CHECK(counter.Next(in_use) == 3);
  CHECK(counter.Next(in_use) == 5);
}

TEST_CASE("embedded handles near the wrap stay distinct from live ones", "[client]") {
  // The counter starts two below the top: the third and later loads come after the wrap. The
  // first load is unloaded, the second stays loaded through a whole turn of the test's loads.
  auto session = MakeEmbeddedSession(1, 0xFFFFFFFEu);
  const RawSamples samples = MakeHeightField(4, 4, 0.5, 0.1, 1);
  TerrainHandle first = 0, kept = 0;
  REQUIRE(session->LoadSamples(samples, "first", &first) == Status::kOk);
  REQUIRE(session->LoadSamples(samples, "kept", &kept) == Status::kOk);
  CHECK(first == 0xFFFFFFFEu);
  CHECK(kept == 0xFFFFFFFFu);
  REQUIRE(session->Unload(first) == Status::kOk);
  std::set<TerrainHandle> seen = {kept};
  for (int i = 0; i < 5; ++i) {
    TerrainHandle h = 0;
    REQUIRE(session->LoadSamples(samples, "t" + std::to_string(i), &h) == Status::kOk);
    CHECK(h != 0);
    CHECK(seen.insert(h).second);
    TerrainInfo info;
    REQUIRE(session->Info(h, &info) == Status::kOk);
    CHECK(info.name == "t" + std::to_string(i));
  }
  TerrainInfo info;
  REQUIRE(session->Info(kept, &info) == Status::kOk);
  CHECK(info.name == "kept");
}
