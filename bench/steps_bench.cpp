// Walk generation: 10,000 hexapods x 100 steps (one crowd, every round of queries one batch),
// with the embedded engine and over RPC against a real footfalld on loopback. The baseline in the
// same run is one hexapod x 100 steps: compare the per_char_step_us counters. Two threads: the
// embedded engine's batches and the generator's own per-character work (footfalld: --threads 2).
#include <benchmark/benchmark.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/scene.h"
#include "server_process.h"

namespace footfall {
namespace {

// 60 x 60 m of gentle bumps at 4 cm spacing (2.25 M samples): room for 10,000 insects 0.5 m
// apart walking 6 m.
const RawSamples& Ground() {
  static const RawSamples s = MakeHeightField(1500, 1500, 0.04, 0.02, 11);
  return s;
}

const Character& Hexapod() {
  static const Character c = [] {
    Character h;
    std::string error;
    if (LoadCharacter(std::string(FOOTFALL_SOURCE_DIR) + "/data/characters/hexapod.json", &h,
                      &error) != Status::kOk)
      throw std::runtime_error(error);
    return h;
  }();
  return c;
}

struct Backend {
  std::unique_ptr<test::ServerProcess> server;
  std::unique_ptr<TerrainSession> session;
  TerrainHandle terrain = 0;
};

Backend& Embedded() {
  static Backend b = [] {
    Backend x;
    x.session = MakeEmbeddedSession(2);
    if (x.session->LoadSamples(Ground(), "bumps", &x.terrain) != Status::kOk)
      throw std::runtime_error(x.session->last_error());
    return x;
  }();
  return b;
}

Backend& Rpc() {
  static Backend b = [] {
    Backend x;
    x.server = std::make_unique<test::ServerProcess>(
        0, std::vector<std::string>{"--no-rpcbind", "--threads", "2"});
    RpcOptions o;
    o.port = x.server->port();
    o.call_timeout_s = 60;
    x.session = MakeRpcSession(o);
    if (x.session->LoadSamples(Ground(), "bumps", &x.terrain) != Status::kOk)
      throw std::runtime_error(x.session->last_error());
    return x;
  }();
  return b;
}

// The crowd walks in passes as GenerateOptions sets them by default (embedded:
// kInProcessCharactersPerPass characters at a time, one pass per thread; RPC: the whole crowd,
// one call per round of queries).
void Walks(benchmark::State& state, Backend& (*backend)()) {
  Backend& b = backend();
  GenerateOptions o;
  o.has_start = true;
  o.start = {30, 0, 27};
  o.crowd = static_cast<int>(state.range(0));
  o.crowd_spacing = 0.5;
  o.steps = static_cast<int>(state.range(1));
  o.threads = 2;
  size_t keys = 0;
  for (auto _ : state) {
    Walk w;
    std::string error;
    if (GenerateWalk(*b.session, b.terrain, Hexapod(), o, &w, &error) != Status::kOk) {
      state.SkipWithError(error.c_str());
      return;
    }
    if (!w.stopped.empty()) {
      state.SkipWithError(w.stopped.c_str());
      return;
    }
    keys = 0;
    for (const WalkTrack& t : w.tracks) keys += t.keys.size();
    benchmark::DoNotOptimize(w);
  }
  const double char_steps = static_cast<double>(o.crowd) * o.steps;
  state.counters["keys"] = static_cast<double>(keys);
  state.counters["char_steps_per_s"] =
      benchmark::Counter(char_steps, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["per_char_step_us"] =
      benchmark::Counter(char_steps * 1e-6, benchmark::Counter::kIsIterationInvariantRate |
                                                benchmark::Counter::kInvert);
}

void BM_WalkEmbedded(benchmark::State& state) { Walks(state, Embedded); }
void BM_WalkRpc(benchmark::State& state) { Walks(state, Rpc); }

BENCHMARK(BM_WalkEmbedded)
    ->ArgNames({"hexapods", "steps"})
    ->Args({1, 100})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WalkEmbedded)
    ->ArgNames({"hexapods", "steps"})
    ->Args({1000, 100})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_WalkEmbedded)
    ->ArgNames({"hexapods", "steps"})
    ->Args({10000, 100})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
BENCHMARK(BM_WalkRpc)
    ->ArgNames({"hexapods", "steps"})
    ->Args({1, 100})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WalkRpc)
    ->ArgNames({"hexapods", "steps"})
    ->Args({10000, 100})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

// A scene of characters that are not one crowd (each with its own start and heading: 40
// hexapods x 50 steps) over RPC: walked at once, their rounds of queries joined into one call
// (GenerateSceneWalks, Arg 1), against the baseline of one after the other (Arg 0).
void BM_SceneRpc(benchmark::State& state) {
  Backend& b = Rpc();
  constexpr int kCharacters = 40;
  std::vector<const Character*> characters(kCharacters, &Hexapod());
  std::vector<GenerateOptions> options(kCharacters);
  for (int i = 0; i < kCharacters; ++i) {
    GenerateOptions& o = options[i];
    o.has_start = true;
    o.start = {5.0 + 1.2 * (i % 8), 0, 5.0 + 5.0 * (i / 8)};
    o.heading = {0.1 * (i % 3 - 1), 0, 1};
    o.steps = 50;
  }
  const bool joined = state.range(0) == 1;
  for (auto _ : state) {
    std::vector<SceneWalk> walks(kCharacters);
    if (joined) {
      GenerateSceneWalks(*b.session, b.terrain, characters, options, &walks);
    } else {
      for (int i = 0; i < kCharacters; ++i)
        walks[i].status = GenerateWalk(*b.session, b.terrain, *characters[i], options[i],
                                       &walks[i].walk, &walks[i].error);
    }
    for (const SceneWalk& w : walks) {
      if (w.status != Status::kOk || !w.walk.stopped.empty()) {
        state.SkipWithError(w.status != Status::kOk ? w.error.c_str() : w.walk.stopped.c_str());
        return;
      }
    }
    benchmark::DoNotOptimize(walks);
  }
  state.SetLabel(joined ? "at once, joined calls" : "one after the other");
  state.counters["per_char_step_us"] =
      benchmark::Counter(kCharacters * 50 * 1e-6, benchmark::Counter::kIsIterationInvariantRate |
                                                      benchmark::Counter::kInvert);
}
BENCHMARK(BM_SceneRpc)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace footfall

BENCHMARK_MAIN();
