// The step generator over RPC against a real footfalld on loopback: a server that dies in the
// middle of a walk leaves the walk made so far, stopped at the step it died in.
#include <atomic>
#include <memory>
#include <string>

#include <catch2/catch.hpp>

#include "counting_session.h"
#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/steps/scene.h"
#include "generator_fixtures.h"
#include "server_process.h"
#include "walk_checks.h"

namespace footfall::test {
namespace {

// True when the two walks have the same tracks with the same keys (frame, phase, position and
// normal to 1e-9) and the same body rotations.
bool SameKeys(const Walk& a, const Walk& b) {
  if (a.tracks.size() != b.tracks.size()) return false;
  for (size_t t = 0; t < a.tracks.size(); ++t) {
    const WalkTrack &x = a.tracks[t], &y = b.tracks[t];
    if (x.name != y.name || x.keys.size() != y.keys.size() ||
        x.rotations.size() != y.rotations.size())
      return false;
    for (size_t i = 0; i < x.keys.size(); ++i) {
      const WalkKey &p = x.keys[i], &q = y.keys[i];
      if (p.frame != q.frame || p.phase != q.phase || Distance(p.position, q.position) > 1e-9 ||
          Distance(p.normal, q.normal) > 1e-9)
        return false;
    }
    for (size_t i = 0; i < x.rotations.size(); ++i) {
      const Quat &p = x.rotations[i], &q = y.rotations[i];
      if (std::fabs(p.w - q.w) + std::fabs(p.x - q.x) + std::fabs(p.y - q.y) +
              std::fabs(p.z - q.z) >
          1e-9)
        return false;
    }
  }
  return true;
}

// `samples` loaded into a real footfalld through an RPC session with short timeouts.
struct ServedTerrain {
  explicit ServedTerrain(const RawSamples& samples) {
    RpcOptions ro;
    ro.port = server.port();
    ro.call_timeout_s = 2;
    ro.connect_timeout_s = 0.5;
    rpc = MakeRpcSession(ro);
    REQUIRE(rpc->LoadSamples(samples, "flat", &handle) == Status::kOk);
  }
  ServerProcess server;
  std::unique_ptr<TerrainSession> rpc;
  TerrainHandle handle = 0;
};

// The walk `o` asks of `c` on `served`, its server killed once the walk has done `kill_after`
// steps.
Walk WalkKillingServer(ServedTerrain& served, const Character& c, GenerateOptions o,
                       int kill_after) {
  o.progress = [&](int done, int) {
    if (done == kill_after) served.server.Kill();
  };
  Walk w;
  std::string error;
  REQUIRE(GenerateWalk(*served.rpc, served.handle, c, o, &w, &error) == Status::kOk);
  return w;
}

}  // namespace

TEST_CASE("A walk over RPC whose server dies keeps its steps up to the one it died in",
          "[steps][rpc]") {
  for (const std::string& name : {std::string("biped"), std::string("hexapod")}) {
    INFO(name);
    const Character c = LoadShipped(name);
    const double spacing = c.step_length / 10;
    const RawSamples samples =
        MakeFlat(static_cast<int>((60 * c.step_length + 8 * c.reach) / spacing), spacing, 0);
    ServedTerrain served(samples);

    // The server is killed once the walk has done `kill_after` steps.
    constexpr int kill_after = 7;
    GenerateOptions o;
    o.has_start = true;
    o.start = {4 * c.reach, 0, 4 * c.reach};
    o.steps = 40;
    const Walk w = WalkKillingServer(served, c, o, kill_after);
    INFO(w.stopped);
    // Stopped at the next step, with the failed call named, its keys those of a walk of
    // kill_after steps.
    CHECK_THAT(w.stopped, Catch::StartsWith("step " + std::to_string(kill_after + 1) + ": "));
    CHECK_THAT(w.stopped, Catch::Contains("footfalld at 127.0.0.1:"));
    CHECK_THAT(w.stopped,
               Catch::EndsWith("keys up to step " + std::to_string(kill_after) + " kept"));
    CHECK(w.session_failed);
    CHECK_THAT(w.stopped, Catch::Contains("footfalld stopped, was killed, or closed it"));
    Terrain t = LoadTerrain(samples, spacing);
    GenerateOptions shorter = o;
    shorter.steps = kill_after;
    const Walk want = Generate(t, c, shorter);
    CHECK(want.stopped.empty());
    CHECK(SameKeys(w, want));
  }
}

TEST_CASE("A crowd over RPC whose server dies says so before the terrain's earlier stops",
          "[steps][rpc]") {
  // (The crowd's message named a terrain stop of one character at step 4, and "and 3 more
  // stopped", hiding that the server's death stopped the others at step 8.)
  const Character c = LoadShipped("biped");
  const double spacing = c.step_length / 10;
  const double side = 60 * c.step_length;
  const RawSamples flat = MakeFlat(static_cast<int>(side / spacing), spacing, 0);
  const Vec3 start{side / 2, 0, 4 * c.reach};
  // The ground ends 3 steps ahead on the low-x half: its characters stop there, at a cliff.
  RawSamples samples;
  for (size_t i = 0; i < flat.size(); ++i) {
    const Vec3& p = flat.points[i];
    if (p.x < start.x && p.z > start.z + 3 * c.step_length) continue;
    samples.points.push_back(p), samples.normals.push_back(flat.normals[i]);
  }
  ServedTerrain served(samples);
  constexpr int kill_after = 7;
  GenerateOptions o;
  o.has_start = true;
  o.start = start;
  o.steps = 40;
  o.crowd = 4;
  o.crowd_spacing = 4 * c.reach;
  const Walk w = WalkKillingServer(served, c, o, kill_after);
  INFO(w.stopped);
  CHECK(w.session_failed);
  REQUIRE(w.stops.size() == 4);
  // The failures first, then the cliff's stops (one at least), earlier.
  size_t failures = 0;
  while (failures < 4 && w.stops[failures].find("footfalld at 127.0.0.1:") != std::string::npos)
    ++failures;
  for (const std::string& stop : w.stops) UNSCOPED_INFO(stop);
  CHECK(failures >= 2);
  CHECK(failures < 4);
  for (size_t i = failures; i < 4; ++i) {
    CHECK_THAT(w.stops[i], Catch::Contains("no foothold"));
    CHECK(std::stoi(w.stops[i].substr(5)) <= kill_after);
  }
  CHECK_THAT(w.stopped, Catch::StartsWith("step " + std::to_string(kill_after + 1) + " of c"));
  CHECK_THAT(w.stopped, Catch::Contains("footfalld at 127.0.0.1:"));
  CHECK_THAT(w.stopped, Catch::EndsWith("(and 3 more characters stopped)"));
  // A walk that stops at the terrain alone is no failure.
  ServedTerrain again(samples);
  Walk cliff;
  std::string error;
  REQUIRE(GenerateWalk(*again.rpc, again.handle, c, o, &cliff, &error) == Status::kOk);
  CHECK_FALSE(cliff.session_failed);
  CHECK(cliff.stops.size() == 2);
  CHECK_THAT(cliff.stopped, Catch::Contains("no foothold"));
}

TEST_CASE("A walk over RPC whose server is gone before its first step fails with the reason",
          "[steps][rpc]") {
  const Character c = LoadShipped("biped");
  const RawSamples samples = MakeFlat(200, 0.07, 0);
  ServedTerrain served(samples);
  served.server.Kill();
  GenerateOptions o;
  o.steps = 10;
  Walk w;
  std::string error;
  CHECK(GenerateWalk(*served.rpc, served.handle, c, o, &w, &error) == Status::kUnavailable);
  CHECK_THAT(error, Catch::Contains("footfalld at 127.0.0.1:"));
  CHECK(w.tracks.empty());
}

TEST_CASE("A scene over RPC walks its characters at once, each as it walks alone, in fewer calls",
          "[steps][rpc][scene]") {
  const double spacing = 0.03;
  const RawSamples samples = MakeHills(300, spacing, 0.05, 7);
  ServedTerrain served(samples);
  Terrain embedded = LoadTerrain(samples, spacing);
  // Characters of every kind, with their own starts, headings, a path and a crowd; the last
  // one's heading is zero, so it fails at once while the others walk.
  std::vector<Character> kinds;
  std::vector<GenerateOptions> options;
  auto add = [&](const std::string& name, Vec3 start, Vec3 heading) {
    kinds.push_back(LoadShipped(name));
    GenerateOptions o;
    o.has_start = true, o.start = start, o.heading = heading, o.steps = 10;
    options.push_back(o);
  };
  add("biped", {1.5, 0.3, 1}, {0, 0, 1});
  add("biped", {3, 0.3, 8}, {0.3, 0, -1});
  add("quadruped", {4.5, 0.3, 1.5}, {0.2, 0, 1});
  add("hexapod", {6.5, 0.3, 1}, {-0.3, 0, 1});
  add("hexapod", {3, 0.3, 5.5}, {1, 0, 0});
  options.back().crowd = 3, options.back().crowd_spacing = 0.4;
  add("octopod", {7.5, 0.3, 7.5}, {0, 0, -1});
  options.back().path = {{7.5, 0, 5.5}, {6, 0, 5.5}};
  add("biped", {5, 0.3, 5}, {0, 0, 0});
  std::vector<const Character*> characters;
  for (const Character& c : kinds) characters.push_back(&c);

  CountingSession joined_calls(*served.rpc);
  std::vector<SceneWalk> walks;
  GenerateSceneWalks(joined_calls, served.handle, characters, options, &walks);
  REQUIRE(walks.size() == characters.size());
  CountingSession alone_calls(*served.rpc);
  for (size_t i = 0; i < characters.size(); ++i) {
    INFO("character " << i << " " << kinds[i].name);
    CHECK(walks[i].walked);
    Walk alone, alone_rpc;
    std::string error;
    const Status want =
        GenerateWalk(*embedded.session, embedded.handle, kinds[i], options[i], &alone, &error);
    CHECK(GenerateWalk(alone_calls, served.handle, kinds[i], options[i], &alone_rpc, &error) ==
          want);
    REQUIRE(walks[i].status == want);
    if (want != Status::kOk) {
      CHECK(i == characters.size() - 1);
      CHECK_FALSE(walks[i].error.empty());
      continue;
    }
    CHECK(walks[i].walk.stopped == "");
    CHECK(SameKeys(walks[i].walk, alone));
    CheckWalk(embedded, kinds[i], options[i], walks[i].walk);
  }
  // One after the other, each character makes its own calls; at once, a round's calls are
  // shared (fewer than half as many here, with six characters of four kinds walking: footfalld
  // takes one tolerance per batch of next queries, so only characters alike share those).
  INFO("joined " << joined_calls.query_calls << " calls, alone " << alone_calls.query_calls);
  CHECK(2 * joined_calls.query_calls < alone_calls.query_calls);
}

TEST_CASE("A scene over RPC whose server dies keeps every character's steps so far",
          "[steps][rpc][scene]") {
  const Character c = LoadShipped("hexapod");
  const double spacing = c.step_length / 5;
  const RawSamples samples = MakeFlat(400, spacing, 0);
  ServedTerrain served(samples);
  constexpr int kCharacters = 5;
  std::vector<const Character*> characters(kCharacters, &c);
  std::vector<GenerateOptions> options(kCharacters);
  std::atomic<bool> killed{false};
  for (int i = 0; i < kCharacters; ++i) {
    options[i].has_start = true;
    options[i].start = {1 + 1.5 * i, 0, 1};
    options[i].steps = 60;
    // The server is killed once the third character has done six steps.
    if (i == 2)
      options[i].progress = [&](int done, int) {
        if (done == 6 && !killed.exchange(true)) served.server.Kill();
      };
  }
  std::vector<SceneWalk> walks;
  GenerateSceneWalks(*served.rpc, served.handle, characters, options, &walks);
  REQUIRE(killed);
  REQUIRE(walks.size() == static_cast<size_t>(kCharacters));
  for (int i = 0; i < kCharacters; ++i) {
    INFO("character " << i);
    CHECK(walks[i].walked);
    REQUIRE(walks[i].status == Status::kOk);
    const Walk& w = walks[i].walk;
    CHECK_THAT(w.stopped, Catch::Contains("footfalld at 127.0.0.1:"));
    CHECK(StepsDone(w) >= 5);
    CHECK(StepsDone(w) < 60);
  }
}

}  // namespace footfall::test
