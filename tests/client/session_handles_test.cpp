// Terrain handles: never 0, never one still loaded, also once the counter wraps past 2^32 - 1;
// the embedded session's failures from several threads at once.
#include <cmath>
#include <set>
#include <string>
#include <thread>
#include <vector>

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

TEST_CASE("embedded queries failing on several threads at once keep last_error whole", "[client]") {
  // Queries may come from several threads at once in process (InProcess); their failures
  // wrote last_error_ at once, which could corrupt the string (and the heap with it).
  auto session = MakeEmbeddedSession();
  TerrainHandle terrain = 0;
  REQUIRE(session->LoadSamples(MakeFlat(4, 1, 0), "flat", &terrain) == Status::kOk);
  std::vector<int> wrong(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      const Vec3 point{1, 0, 1};
      Foothold out;
      for (int i = 0; i < 100000; ++i) {
        // An unknown handle, one per thread (messages of different lengths), and a bad tolerance.
        const TerrainHandle unknown = terrain + 1 + static_cast<TerrainHandle>(t) * 1000003u;
        wrong[t] += session->Snap(unknown, &point, 1, &out) != Status::kUnknownTerrain;
        const StepQuery step{point, {0.5, 0, 0}};
        wrong[t] +=
            session->Next(terrain, &step, 1, std::nan(""), &out) != Status::kInvalidArgument;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < 4; ++t) CHECK(wrong[t] == 0);
  const std::string& last = session->last_error();
  CHECK((last == "tolerance is not finite" || last.rfind("no terrain with handle ", 0) == 0));
}
