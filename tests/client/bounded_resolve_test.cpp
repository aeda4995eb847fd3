// Host name lookups bounded by the session's call timeout: a resolver that does not answer no
// longer blocks a client call indefinitely; literal addresses need no lookup at all.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "rpc_connect.h"

using namespace footfall;

namespace {

std::atomic<int> g_calls{0};
std::atomic<int> g_finished{0};
std::mutex g_mutex;
std::condition_variable g_cv;
bool g_release = false;

// A resolver that does not answer until the test releases it, then answers 127.0.0.1.
int StuckResolver(const char*, const char* service, const addrinfo* hints, addrinfo** out) {
  ++g_calls;
  {
    std::unique_lock<std::mutex> lock(g_mutex);
    g_cv.wait(lock, [] { return g_release; });
  }
  const int code = getaddrinfo("127.0.0.1", service, hints, out);
  ++g_finished;
  return code;
}

int CountingResolver(const char*, const char* service, const addrinfo* hints, addrinfo** out) {
  ++g_calls;
  return getaddrinfo("127.0.0.1", service, hints, out);
}

void Reset() {
  g_calls = 0;
  g_finished = 0;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_release = false;
}

// Lets every stuck lookup answer and waits until `count` of them have ended.
void ReleaseAndWait(int count) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_release = true;
  }
  g_cv.notify_all();
  for (int i = 0; i < 500 && g_finished.load() < count; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  REQUIRE(g_finished.load() == count);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // past their last lines
}

addrinfo StreamHints() {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  return hints;
}

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Loads a tiny terrain on `session` into *status; returns how long the call took [Units: s].
double TimeTinyLoad(TerrainSession& session, Status* status) {
  TerrainHandle handle = 0;
  const auto t0 = std::chrono::steady_clock::now();
  *status = session.LoadSamples(MakeHeightField(4, 4, 0.5, 0.1, 1), "t", &handle);
  return SecondsSince(t0);
}

// A loopback listener whose accept queue is full: connection attempts get no answer (their
// connect waits) until Close, after which retried handshakes are refused.
class DroppingListener {
 public:
  DroppingListener() {
    listener_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0);
    REQUIRE(listen(listener_, 0) == 0);
    socklen_t length = sizeof address;
    REQUIRE(getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length) == 0);
    port_ = ntohs(address.sin_port);
    for (int i = 0; i < 2; ++i) {  // fill the accept queue
      queued_.push_back(socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0));
      connect(queued_.back(), reinterpret_cast<sockaddr*>(&address), sizeof address);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  ~DroppingListener() { Close(); }
  DroppingListener(const DroppingListener&) = delete;
  DroppingListener& operator=(const DroppingListener&) = delete;

  int port() const { return port_; }
  void Close() {
    for (const int fd : queued_) close(fd);
    queued_.clear();
    if (listener_ >= 0) close(listener_);
    listener_ = -1;
  }

 private:
  int listener_ = -1;
  int port_ = 0;
  std::vector<int> queued_;
};

}  // namespace

TEST_CASE("literal addresses are resolved without a name lookup", "[client]") {
  Reset();
  for (const char* host : {"127.0.0.1", "::1", "10.1.2.3"}) {
    addrinfo* found = nullptr;
    std::string reason;
    REQUIRE(ResolveBounded(host, "7407", StreamHints(), 0.5, &StuckResolver, &found, &reason));
    REQUIRE(found != nullptr);
    freeaddrinfo(found);
  }
  CHECK(g_calls.load() == 0);
  addrinfo* found = nullptr;
  std::string reason;
  REQUIRE(
      ResolveBounded("some.name", "7407", StreamHints(), 0.5, &CountingResolver, &found, &reason));
  CHECK(g_calls.load() == 1);
  REQUIRE(found != nullptr);
  freeaddrinfo(found);
}

TEST_CASE("a name lookup that does not answer is abandoned after the timeout", "[client]") {
  Reset();
  addrinfo* found = nullptr;
  std::string reason;
  const auto t0 = std::chrono::steady_clock::now();
  CHECK_FALSE(
      ResolveBounded("stuck.test", "7407", StreamHints(), 0.2, &StuckResolver, &found, &reason));
  CHECK(SecondsSince(t0) < 2);
  CHECK(found == nullptr);
  CHECK(reason == "cannot resolve host: no answer from the name lookup within 0.2 s");
  ReleaseAndWait(1);  // its thread frees the late answer
}

TEST_CASE("at most a few abandoned name lookups run at once", "[client]") {
  Reset();
  std::string reason;
  addrinfo* found = nullptr;
  for (int i = 0; i < kMaxPendingLookups; ++i)
    REQUIRE_FALSE(
        ResolveBounded("stuck.test", "7407", StreamHints(), 0.01, &StuckResolver, &found, &reason));
  const auto t0 = std::chrono::steady_clock::now();
  CHECK_FALSE(
      ResolveBounded("stuck.test", "7407", StreamHints(), 5, &StuckResolver, &found, &reason));
  CHECK(SecondsSince(t0) < 1);
  CHECK(reason == "cannot resolve host: 8 earlier lookups are still unanswered");
  CHECK(g_calls.load() == kMaxPendingLookups);
  ReleaseAndWait(kMaxPendingLookups);
  // Once they have ended, names are looked up again.
  REQUIRE(
      ResolveBounded("some.name", "7407", StreamHints(), 1, &CountingResolver, &found, &reason));
  freeaddrinfo(found);
}

TEST_CASE("an RPC session whose host lookup hangs fails within its call timeout", "[client]") {
  Reset();
  SetHostResolver(&StuckResolver);
  RpcOptions options;
  options.host = "footfalld.stuck.test";
  options.port = 7407;
  options.call_timeout_s = 0.3;
  auto session = MakeRpcSession(options);
  Status status = Status::kOk;
  const double waited = TimeTinyLoad(*session, &status);
  SetHostResolver(nullptr);
  CHECK(status == Status::kUnavailable);
  CHECK(waited < 2);
  CHECK(session->last_error() ==
        "footfalld at footfalld.stuck.test:7407: cannot resolve host: no answer from the name "
        "lookup within 0.3 s");
  session.reset();
  ReleaseAndWait(1);
}

TEST_CASE("a connect interrupted by a signal still ends within the connect timeout", "[client]") {
  // A host that drops connection attempts (a listener whose accept queue is full), and a
  // caller whose signal handler runs during the connect, as Python's, Go's and DCCs' do: the
  // interrupted wait was read as connected, and libtirpc then waited about 130 s for the
  // connect with every signal blocked.
  DroppingListener host;
  struct sigaction handler {
  }, old_handler{};
  handler.sa_handler = [](int) {};
  handler.sa_flags = SA_RESTART;
  REQUIRE(sigaction(SIGALRM, &handler, &old_handler) == 0);
  itimerval once{{0, 0}, {0, 200000}};  // one signal, 0.2 s into the connect
  setitimer(ITIMER_REAL, &once, nullptr);

  RpcOptions options;
  options.host = "127.0.0.1";
  options.port = host.port();
  options.connect_timeout_s = 1;
  options.call_timeout_s = 1;
  auto session = MakeRpcSession(options);
  Status status = Status::kOk;
  const double waited = TimeTinyLoad(*session, &status);
  sigaction(SIGALRM, &old_handler, nullptr);
  host.Close();
  CHECK(status == Status::kUnavailable);
  INFO(session->last_error());
  CHECK(session->last_error().find("connection timed out") != std::string::npos);
  CHECK(waited < 20);  // about the 1 s timeout; never the kernel's 130 s
}

TEST_CASE("infinite and huge timeouts are bounded instead of overflowing", "[client]") {
  // A connect timeout past 2^31 ms reached poll() wrapped round: 2^32 ms + 0.2 s (49.7 days)
  // gave up after 0.2 s, "connection timed out"; infinity overflowed the deadline's clock
  // arithmetic. Here the host drops connection attempts until its listener closes 0.6 s in;
  // the retried handshake is then refused.
  const double connect_timeout =
      GENERATE(4294967.296 + 0.2, std::numeric_limits<double>::infinity());
  DroppingListener host;
  std::thread closer([&host] {
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    host.Close();
  });

  RpcOptions options;
  options.host = "127.0.0.1";
  options.port = host.port();
  options.connect_timeout_s = connect_timeout;
  options.call_timeout_s = 1e300;
  options.busy_timeout_s = std::numeric_limits<double>::quiet_NaN();
  auto session = MakeRpcSession(options);
  Status status = Status::kOk;
  const double waited = TimeTinyLoad(*session, &status);
  closer.join();
  CHECK(status == Status::kUnavailable);
  INFO(session->last_error());
  CHECK(session->last_error().find("timed out") == std::string::npos);
  CHECK(waited > 0.5);  // it waited for the host, until the host refused
  CHECK(waited < 20);
}
