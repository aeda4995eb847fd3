// footfalld while memory runs short: C++ allocations fail at random points of its work (loads,
// uploads, queries, its main loop, its worker threads) through a preloaded operator new. It must
// neither crash nor lose a terrain a client loaded before, and must serve normally once memory
// is back.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "server_process.h"

using namespace footfall;
using footfall::test::ServerProcess;

namespace {

// Short timeouts: while every few allocations fail, the server answers little.
std::unique_ptr<TerrainSession> Connect(int port) {
  RpcOptions o;
  o.port = port;
  o.call_timeout_s = 1;
  o.busy_timeout_s = 0.5;
  o.load_timeout_s = 5;
  return MakeRpcSession(o);
}

// A few seconds of every kind of request, from several connections at once; their answers
// (errors while memory is short) are not checked here.
void Churn(int port, int seed) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(2000);
  std::vector<Vec3> points;
  std::vector<StepQuery> steps;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p{(i * 7 % 100) * 0.1, 1.0, (i * 13 % 100) * 0.1};
    points.push_back(p);
    steps.push_back({p, {0.3, 0, 0.1}});
  }
  std::vector<Foothold> answers(points.size());
  for (int round = 0; std::chrono::steady_clock::now() < end; ++round) {
    auto session = Connect(port);
    TerrainHandle handle = 0;
    if (session->LoadSamples(MakeHeightField(40, 40, 0.25, 1.0, seed + round), "churn", &handle) !=
        Status::kOk)
      continue;
    session->Snap(handle, points.data(), points.size(), answers.data());
    session->Next(handle, steps.data(), steps.size(), 0, answers.data());
    session->Normal(handle, points.data(), points.size(), answers.data());
    if (round % 2) session->Unload(handle);
  }
}

}  // namespace

TEST_CASE("footfalld survives C++ allocations failing anywhere, and loses no terrain",
          "[rpc][memory]") {
  char flag[] = "/tmp/footfall-fail-new-XXXXXX";
  const int fd = mkstemp(flag);
  REQUIRE(fd >= 0);
  close(fd);
  std::remove(flag);  // allocations fail while it exists
  setenv("LD_PRELOAD", FAILING_NEW_PATH, 1);
  setenv("FOOTFALL_FAIL_NEW_WHILE", flag, 1);
  const int every = GENERATE(5, 37);
  setenv("FOOTFALL_FAIL_NEW_EVERY", std::to_string(every).c_str(), 1);
  ServerProcess server(0, {"--no-rpcbind", "--threads", "2"});
  unsetenv("LD_PRELOAD");
  unsetenv("FOOTFALL_FAIL_NEW_WHILE");
  unsetenv("FOOTFALL_FAIL_NEW_EVERY");
  INFO("every " << every << "th allocation fails");

  // A terrain loaded before memory runs short.
  auto keeper = Connect(server.port());
  TerrainHandle kept = 0;
  const RawSamples samples = MakeHeightField(60, 60, 0.25, 1.0, 7);
  REQUIRE(keeper->LoadSamples(samples, "kept", &kept) == Status::kOk);
  const Foothold before = keeper->Snap(kept, {5, 1, 5});
  REQUIRE(before.status == Status::kOk);

  {
    FILE* f = std::fopen(flag, "w");
    REQUIRE(f);
    std::fclose(f);
  }
  std::vector<std::thread> clients;
  for (int c = 0; c < 3; ++c) clients.emplace_back(Churn, server.port(), 100 * c);
  for (int i = 0; i < 10; ++i) {  // the keeper queries too
    keeper->Snap(kept, {5, 1, 5});
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (std::thread& t : clients) t.join();
  std::remove(flag);

  int status = 0;
  const pid_t ended = waitpid(server.pid(), &status, WNOHANG);
  INFO(server.Log());
  REQUIRE(ended == 0);  // still running: no abort, no crash
  // The terrain loaded before is answered as before (over its connection, or reloaded by the
  // client library on a new one), and new clients are served.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const Foothold after = keeper->Snap(kept, {5, 1, 5});
  INFO(keeper->last_error());
  REQUIRE(after.status == Status::kOk);
  CHECK(after.index == before.index);
  auto fresh = Connect(server.port());
  TerrainHandle handle = 0;
  const Status loaded = fresh->LoadSamples(samples, "fresh", &handle);
  INFO(fresh->last_error());
  REQUIRE(loaded == Status::kOk);
  CHECK(fresh->Snap(handle, {5, 1, 5}).index == before.index);
  CHECK(server.Terminate() == 0);
}
