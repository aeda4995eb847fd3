// footfalld while memory runs short: C++ allocations fail at random points of its work (loads,
// uploads, queries, its main loop, its worker threads) through a preloaded operator new. It must
// neither crash nor lose a terrain a client loaded before, and must serve normally once memory
// is back.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "raw_rpc.h"
#include "server_process.h"

using namespace footfall;
using footfall::test::ServerProcess;

namespace {

// Short timeouts: while every few allocations fail, the server answers little.
std::unique_ptr<TerrainSession> Connect(int port) {
  RpcOptions o;
  o.port = port;
  o.call_timeout_s = 3;
  o.busy_timeout_s = 0.5;
  o.load_timeout_s = 5;
  return MakeRpcSession(o);
}

// Whether the last call of `session`, which returned `s`, waited out its timeout: footfalld
// never answered it.
bool Unanswered(Status s, const TerrainSession& session) {
  return s == Status::kUnavailable && session.last_error().find("Timed out") != std::string::npos;
}

// A few seconds of every kind of request, from several connections at once; their answers
// (errors while memory is short) are not checked here, but every request must be answered and
// every failure said: those that were not are counted in `unanswered`, and failures with an
// empty last_error() in `unexplained`; the errors of both are kept in `errors`.
void Churn(int port, int seed, std::atomic<int>* unanswered, std::atomic<int>* unexplained,
           std::vector<std::string>* errors) {
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
    auto note = [&](Status s) {
      if (s != Status::kOk && session->last_error().empty()) {
        ++*unexplained;  // a failure without a word of why
        errors->push_back("(no error text) status " + std::string(StatusName(s)));
      }
      if (!Unanswered(s, *session)) return s;
      ++*unanswered;
      errors->push_back(session->last_error());
      return s;
    };
    TerrainHandle handle = 0;
    if (note(session->LoadSamples(MakeHeightField(40, 40, 0.25, 1.0, seed + round), "churn",
                                  &handle)) != Status::kOk)
      continue;
    note(session->Snap(handle, points.data(), points.size(), answers.data()));
    note(session->Next(handle, steps.data(), steps.size(), 0, answers.data()));
    note(session->Normal(handle, points.data(), points.size(), answers.data()));
    if (round % 2) note(session->Unload(handle));
  }
}

// A footfalld whose C++ allocations fail, every `every`-th, while Fail() is in force.
class FailingServer {
 public:
  // `args`: footfalld's flags beside --no-rpcbind and --threads 2.
  explicit FailingServer(int every, const std::vector<std::string>& args = {}) {
    char flag[] = "/tmp/footfall-fail-new-XXXXXX";
    const int fd = mkstemp(flag);
    if (fd < 0) throw std::runtime_error("mkstemp failed");
    close(fd);
    flag_ = flag;
    Recover();
    setenv("LD_PRELOAD", FAILING_NEW_PATH, 1);
    setenv("FOOTFALL_FAIL_NEW_WHILE", flag_.c_str(), 1);
    setenv("FOOTFALL_FAIL_NEW_EVERY", std::to_string(every).c_str(), 1);
    std::vector<std::string> flags{"--no-rpcbind", "--threads", "2"};
    flags.insert(flags.end(), args.begin(), args.end());
    server_ = std::make_unique<ServerProcess>(0, flags);
    unsetenv("LD_PRELOAD");
    unsetenv("FOOTFALL_FAIL_NEW_WHILE");
    unsetenv("FOOTFALL_FAIL_NEW_EVERY");
  }
  ~FailingServer() { Recover(); }
  FailingServer(const FailingServer&) = delete;
  FailingServer& operator=(const FailingServer&) = delete;

  ServerProcess& server() { return *server_; }
  // Allocations fail from now on (after the first `spared`, which succeed).
  void Fail(long spared = 0) {
    FILE* f = std::fopen(flag_.c_str(), "w");
    if (!f) throw std::runtime_error("cannot create " + flag_);
    std::fprintf(f, "%ld\n", spared);
    std::fclose(f);
  }
  // Memory is back.
  void Recover() { std::remove(flag_.c_str()); }

 private:
  std::string flag_;
  std::unique_ptr<ServerProcess> server_;
};

}  // namespace

TEST_CASE("footfalld survives C++ allocations failing anywhere, and loses no terrain",
          "[rpc][memory]") {
  const int every = GENERATE(1, 5, 37);  // 1: every allocation fails
  INFO("every " << every << "th allocation fails");
  FailingServer failing(every);
  ServerProcess& server = failing.server();

  // A terrain loaded before memory runs short.
  auto keeper = Connect(server.port());
  TerrainHandle kept = 0;
  const RawSamples samples = MakeHeightField(60, 60, 0.25, 1.0, 7);
  REQUIRE(keeper->LoadSamples(samples, "kept", &kept) == Status::kOk);
  const Foothold before = keeper->Snap(kept, {5, 1, 5});
  REQUIRE(before.status == Status::kOk);

  failing.Fail();
  std::vector<std::thread> clients;
  std::atomic<int> unanswered{0}, unexplained{0};
  std::vector<std::vector<std::string>> errors(3);
  for (int c = 0; c < 3; ++c)
    clients.emplace_back(Churn, server.port(), 100 * c, &unanswered, &unexplained, &errors[c]);
  int keeper_unanswered = 0;
  for (int i = 0; i < 10; ++i) {  // the keeper queries too
    const Vec3 at{5, 1, 5};
    Foothold answer;
    if (Unanswered(keeper->Snap(kept, &at, 1, &answer), *keeper)) ++keeper_unanswered;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (std::thread& t : clients) t.join();
  failing.Recover();

  int status = 0;
  const pid_t ended = waitpid(server.pid(), &status, WNOHANG);
  INFO(server.Log());
  REQUIRE(ended == 0);  // still running: no abort, no crash
  // Every request was answered, if only with an error: a request libtirpc had read but that
  // never reached the dispatcher (an exception thrown across libtirpc) left its client waiting.
  for (const auto& list : errors)
    for (const std::string& e : list) UNSCOPED_INFO(e);
  CHECK(unanswered.load() == 0);
  CHECK(unexplained.load() == 0);
  CHECK(keeper_unanswered == 0);
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

TEST_CASE("footfalld answers its first client while every allocation fails", "[rpc][memory]") {
  // Memory runs out before anybody connects: the lists footfalld's loop fills at every turn
  // have their room from the start, so the first requests are read and answered (with errors).
  FailingServer failing(1);
  failing.Fail();
  auto session = Connect(failing.server().port());
  TerrainHandle handle = 0;
  const RawSamples samples = MakeHeightField(20, 20, 0.25, 1.0, 3);
  const Status refused = session->LoadSamples(samples, "first", &handle);
  INFO(session->last_error());
  CHECK(refused != Status::kOk);
  CHECK_FALSE(Unanswered(refused, *session));
  CHECK_THAT(session->last_error(), Catch::Contains("ran out of memory"));
  failing.Recover();
  const Status loaded = session->LoadSamples(samples, "first", &handle);
  INFO(session->last_error());
  REQUIRE(loaded == Status::kOk);
  CHECK(session->Snap(handle, {1, 1, 1}).status == Status::kOk);
  CHECK(failing.server().Terminate() == 0);
}

TEST_CASE("footfalld serves others while a client never reads and every allocation fails",
          "[rpc][memory]") {
  // A connection without room for its replies is polled for room at every turn; noting it must
  // not need memory, or no turn got as far as reading anybody's request.
  FailingServer failing(1);
  const int port = failing.server().port();
  auto keeper = Connect(port);
  TerrainHandle kept = 0;
  REQUIRE(keeper->LoadSamples(MakeHeightField(30, 30, 0.25, 1.0, 5), "kept", &kept) == Status::kOk);
  REQUIRE(keeper->Snap(kept, {3, 1, 3}).status == Status::kOk);
  std::vector<uint32_t> handles;
  REQUIRE(footfall::test::ListServerTerrains(port, &handles));
  REQUIRE(handles.size() == 1);
  footfall::test::Flooder flooder(port, footfall::test::FullBatchCall(handles[0]));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (flooder.blocked() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  REQUIRE(flooder.blocked() > 0);  // its socket is full: footfalld holds it back

  failing.Fail();
  for (int i = 0; i < 5; ++i) {
    const Vec3 at{3, 1, 3};
    Foothold answer;
    const Status s = keeper->Snap(kept, &at, 1, &answer);
    INFO(keeper->last_error());
    CHECK_FALSE(Unanswered(s, *keeper));
  }
  failing.Recover();
  CHECK(keeper->Snap(kept, {3, 1, 3}).status == Status::kOk);
  CHECK(flooder.drops() == 0);
}

TEST_CASE("footfalld answers server-side loads while memory runs out and stays out",
          "[rpc][memory]") {
  // A load thread handed its finished load back into a list that grew: with memory gone it
  // waited for memory to come back, and the client waited out its load timeout (300 s by
  // default). The list now has room for every load the queue may hold.
  char root[] = "/tmp/footfall-memory-root-XXXXXX";
  REQUIRE(mkdtemp(root));
  const std::string dir = root;
  struct Cleanup {
    std::string dir;
    ~Cleanup() { std::system(("rm -rf '" + dir + "'").c_str()); }
  } cleanup{dir};
  auto write = [&](const std::string& name, const std::string& text) {
    FILE* f = std::fopen((dir + "/" + name).c_str(), "w");
    REQUIRE(f);
    std::fputs(text.c_str(), f);
    std::fclose(f);
  };
  std::string pts, obj, asc = "ncols 12\nnrows 12\nxllcorner 0\nyllcorner 0\ncellsize 0.5\n";
  for (int i = 0; i < 12; ++i) {
    for (int k = 0; k < 12; ++k) {
      const double y = 0.05 * ((i * 7 + k * 3) % 5);
      pts += std::to_string(0.5 * i) + " " + std::to_string(y) + " " + std::to_string(0.5 * k) +
             " 0 1 0\n";
      obj += "v " + std::to_string(0.5 * i) + " " + std::to_string(y) + " " +
             std::to_string(0.5 * k) + "\n";
      asc += std::to_string(y) + (k == 11 ? "\n" : " ");
    }
  }
  for (int i = 0; i < 11; ++i) {
    for (int k = 0; k < 11; ++k) {
      const int a = i * 12 + k + 1, b = a + 1, c = a + 12, d = c + 1;  // OBJ counts from 1
      obj += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(d) + "\n";
      obj += "f " + std::to_string(a) + " " + std::to_string(d) + " " + std::to_string(c) + "\n";
    }
  }
  write("ground.pts", pts);
  write("ground.obj", obj);
  write("ground.asc", asc);

  FailingServer failing(1, {"--data-root", dir});
  const int port = failing.server().port();
  TerrainLoadOptions options;
  options.separation = 0.25;
  int refused = 0;
  for (const char* name : {"ground.pts", "ground.asc", "ground.obj"}) {
    // The first failure moved through the load: the request, the file's reading and
    // resampling, the grid, the reply.
    for (long spared = 0; spared <= 3000; spared = spared < 10 ? spared + 1 : spared * 3 / 2) {
      INFO(name << ", allocations failing after the first " << spared);
      auto session = Connect(port);
      failing.Fail(spared);
      TerrainHandle handle = 0;
      const Status s = session->LoadServerFile(name, options, &handle);
      failing.Recover();
      INFO(session->last_error());
      CHECK_FALSE(Unanswered(s, *session));
      if (s != Status::kOk) {
        ++refused;
        CHECK_FALSE(session->last_error().empty());
      }
      int status = 0;
      REQUIRE(waitpid(failing.server().pid(), &status, WNOHANG) == 0);  // still serving
    }
    // Memory back: the same load succeeds.
    auto session = Connect(port);
    TerrainHandle handle = 0;
    const Status s = session->LoadServerFile(name, options, &handle);
    INFO(name << ": " << session->last_error());
    REQUIRE(s == Status::kOk);
    CHECK(session->Snap(handle, {1, 1, 1}).status == Status::kOk);
  }
  CHECK(refused > 0);  // memory did run out in those loads
  CHECK(failing.server().Terminate() == 0);
}
