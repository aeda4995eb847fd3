// The step generator over RPC against a real footfalld on loopback: a server that dies in the
// middle of a walk leaves the walk made so far, stopped at the step it died in.
#include <memory>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
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
    o.progress = [&](int done, int) {
      if (done == kill_after) served.server.Kill();
    };
    Walk w;
    std::string error;
    REQUIRE(GenerateWalk(*served.rpc, served.handle, c, o, &w, &error) == Status::kOk);
    INFO(w.stopped);
    // Stopped at the next step, with the failed call named, its keys those of a walk of
    // kill_after steps.
    CHECK_THAT(w.stopped, Catch::StartsWith("step " + std::to_string(kill_after + 1) + ": "));
    CHECK_THAT(w.stopped, Catch::Contains("footfalld at 127.0.0.1:"));
    CHECK_THAT(w.stopped,
               Catch::EndsWith("keys up to step " + std::to_string(kill_after) + " kept"));
    Terrain t = LoadTerrain(samples, spacing);
    GenerateOptions shorter = o;
    shorter.progress = nullptr;
    shorter.steps = kill_after;
    const Walk want = Generate(t, c, shorter);
    CHECK(want.stopped.empty());
    CHECK(SameKeys(w, want));
  }
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

}  // namespace footfall::test
