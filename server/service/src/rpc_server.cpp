#include "footfall/service/rpc_server.h"

#include <arpa/inet.h>
#include <malloc.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <rpc/pmap_clnt.h>
#include <rpc/rpc.h>
#include <rpc/rpc_com.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "deferred_reply.h"
#include "dispatcher.h"
#include "footfall.h"
#include "partial_requests.h"
#include "read_gate.h"
#include "reserve_ahead.h"
#include "service_log.h"

namespace footfall {
namespace {

constexpr int kListenBacklog = 1024;  // 64 dropped SYNs in bursts of connects
std::unique_ptr<ServiceState> g_state;

// [Units: connections] How many may hold part of a request at once (about 270 KB each at most,
// in libtirpc's record buffers): past it, the one holding its part longest is closed. A request
// of a client on the same network arrives within milliseconds: only stalled ones count up.
constexpr size_t kMaxPartialRequests = 64;
std::unique_ptr<PartialRequests> g_partial;
DispatchFn g_dispatch = nullptr;

// The serving loop's own lists, made by Start before it says it listens: a server that has
// said so does not then stop for want of memory to begin serving.
struct LoopState {
  LoopState(size_t send_buffer, double unread_timeout_s) : gate(send_buffer, unread_timeout_s) {
    ReserveAhead(&fds, 1);       // the least room, from the start: memory may run out before the
    ReserveAhead(&readable, 1);  // first client comes
    ReserveAhead(&held, 1);
  }
  ReadGate gate;
  std::vector<pollfd> fds, readable;
  std::vector<int> held;  // reused: a turn allocates nothing once its lists have grown
};
std::unique_ptr<LoopState> g_loop;

// The dispatcher, noting which connections had a whole request.
void NotedDispatch(svc_req* request, SVCXPRT* transport) {
  g_partial->Dispatched(transport->xp_fd);
  g_dispatch(request, transport);
}

// True when something accepts TCP connections on 127.0.0.1:111 (rpcbind), checked without
// waiting on libtirpc's long timeouts.
bool RpcbindRunning() {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(111);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool up = connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  close(fd);
  return up;
}

// The port rpcbind has for footfall's program when a server still accepts connections there
// (another footfalld), else 0.
int LiveRegisteredPort() {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const unsigned short port = pmap_getport(&a, FOOTFALL_PROG, FOOTFALL_V1, IPPROTO_TCP);
  if (port == 0) return 0;
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return 0;
  a.sin_port = htons(port);
  const bool live = connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  close(fd);
  return live ? port : 0;
}

}  // namespace

RpcServer::RpcServer(RpcServerOptions options) : options_(std::move(options)) {}

RpcServer::~RpcServer() {
  // libtirpc's svc_unregister also unsets the program at rpcbind, whoever registered it: a
  // server that did not register (another footfalld had) must leave rpcbind alone, and its
  // dispatch entry goes with the process.
  if (registered_rpcbind_) {
    pmap_unset(FOOTFALL_PROG, FOOTFALL_V1);
    svc_unregister(FOOTFALL_PROG, FOOTFALL_V1);
  }
}

bool RpcServer::Start(std::string* error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(options_.port);
  const int gai = getaddrinfo(options_.listen_host.c_str(), port.c_str(), &hints, &found);
  if (gai != 0) {
    *error = "cannot resolve listen address '" + options_.listen_host + "': " + gai_strerror(gai);
    return false;
  }
  std::string reason = "no address";
  for (addrinfo* a = found; a && listen_fd_ < 0; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    // Accepted connections inherit the send buffer: room for a largest reply beside another
    // (the kernel doubles the value, and caps it at net.core.wmem_max).
    const int send_buffer = static_cast<int>(kReplyRoomBytes);
    setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &send_buffer, sizeof send_buffer);
    if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 || listen(fd, kListenBacklog) != 0) {
      reason = std::strerror(errno);
      close(fd);
      continue;
    }
    listen_fd_ = fd;
  }
  freeaddrinfo(found);
  if (listen_fd_ < 0) {
    const bool v6 = options_.listen_host.find(':') != std::string::npos;
    *error = "cannot listen on " + (v6 ? "[" + options_.listen_host + "]" : options_.listen_host) +
             ":" + port + ": " + reason;
    return false;
  }
  sockaddr_storage bound{};
  socklen_t len = sizeof bound;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
  // A wildcard address ("0", "0.0.0.0", "::") listens on every interface: said when listening.
  every_interface_ =
      bound.ss_family == AF_INET6
          ? IN6_IS_ADDR_UNSPECIFIED(&reinterpret_cast<sockaddr_in6*>(&bound)->sin6_addr)
          : reinterpret_cast<sockaddr_in*>(&bound)->sin_addr.s_addr == htonl(INADDR_ANY);
  int send_buffer = 0;
  len = sizeof send_buffer;
  getsockopt(listen_fd_, SOL_SOCKET, SO_SNDBUF, &send_buffer, &len);
  send_buffer_ = static_cast<size_t>(send_buffer);
  if (send_buffer_ < kReplyRoomBytes)
    std::fprintf(stderr,
                 "footfalld: warning: the socket send buffer is %zu bytes, less than a full batch "
                 "reply needs (%zu): raise net.core.wmem_max\n",
                 send_buffer_, kReplyRoomBytes);

  // Every connection's record buffers (FF_MAX_REQUEST_BYTES and more each way) mapped on their
  // own, as glibc does at first: its threshold otherwise rises to their size once one is
  // freed, and later connections then took theirs from the heap, kept resident and written
  // whole (200 idle connections after a burst of half-sent requests held 54 MB; 4 MB before).
  // Smaller blocks stay in the heap: a decoded upload chunk (192 KiB) mapped and unmapped at
  // every call took 30% more of the server's time for an upload.
  mallopt(M_MMAP_THRESHOLD, FF_MAX_REQUEST_BYTES);
  // Non-blocking transports with a bounded record size: a half-sent request cannot stall the
  // loop (ReadGate holds back clients that never read). Must be set before the transport is
  // created. The record limit is the receive buffer itself (libtirpc caps it at 256 KiB,
  // FF_MAX_REQUEST_BYTES): a fragment announced past the buffer but within a larger limit made
  // libtirpc grow the buffer, after which it took the half-received record for one still
  // holding requests and read it again and again, serving no one else, until the rest came.
  int max_record = FF_MAX_REQUEST_BYTES;
  rpc_control(RPC_SVC_CONNMAXREC_SET, &max_record);
  SVCXPRT* transport = svc_vc_create(listen_fd_, FF_MAX_REQUEST_BYTES, FF_MAX_REQUEST_BYTES);
  if (!transport) {
    *error = "cannot create the RPC transport";
    return false;
  }
  g_state = std::make_unique<ServiceState>(
      ServiceState{TerrainRegistry(options_.data_root, options_.limits),
                   options_.batch_threads,
                   options_.batch_time_limit_s,
                   {},
                   1,
                   {}});
  g_dispatch = InstallDispatcher(g_state.get());
  g_partial = std::make_unique<PartialRequests>(options_.request_timeout_s, kMaxPartialRequests);
  WatchListener(transport);
  if (!svc_register(transport, FOOTFALL_PROG, FOOTFALL_V1, NotedDispatch, 0)) {
    *error = "cannot register the RPC program";
    return false;
  }
  // Registered with rpcbind before on_bound (footfalld's --port-file), so that a client
  // which waits for the port file finds the registration too; said after it. A failing on_bound
  // leaves the registration to the destructor, which withdraws it.
  std::string rpcbind_note;
  if (options_.use_rpcbind) {
    const int other = RpcbindRunning() ? LiveRegisteredPort() : 0;
    if (other != 0 && other != port_) {
      // Taking the registration over would leave that server unregistered once this one stops.
      rpcbind_note = "rpcbind already has the footfalld on port " + std::to_string(other) +
                     "; not registering (clients connect to this one by port)";
    } else if (RpcbindRunning()) {
      pmap_unset(FOOTFALL_PROG, FOOTFALL_V1);  // a stale registration of a server gone
      registered_rpcbind_ =
          pmap_set(FOOTFALL_PROG, FOOTFALL_V1, IPPROTO_TCP, static_cast<unsigned short>(port_));
      rpcbind_note =
          registered_rpcbind_ ? "registered with rpcbind" : "rpcbind refused the registration";
    } else {
      rpcbind_note = "rpcbind is not running; clients connect by port";
    }
  }
  // Everything that needs memory is made before on_bound: once the port file is written and the
  // server has said it listens, starting cannot fail.
  g_loop = std::make_unique<LoopState>(send_buffer_, options_.unread_timeout_s);
  const std::string data_root_note =
      options_.data_root.empty() ? "" : "footfalld: data root " + EscapeControl(options_.data_root);
  // Nothing says the server listens until on_bound has succeeded: a server that then exits was
  // never announced.
  if (options_.on_bound && !options_.on_bound(port_, error)) return false;
  const bool v6 = options_.listen_host.find(':') != std::string::npos;
  std::fprintf(stderr, "footfalld: listening on %s%s%s:%d (program %u version %u)\n", v6 ? "[" : "",
               options_.listen_host.c_str(), v6 ? "]" : "", port_,
               static_cast<unsigned>(FOOTFALL_PROG), static_cast<unsigned>(FOOTFALL_V1));
  if (every_interface_) {
    std::fprintf(stderr,
                 "footfalld: warning: listening on every interface: any host that reaches this "
                 "machine may load and query terrains (--listen 127.0.0.1:%d serves this machine "
                 "only)\n",
                 port_);
  }
  if (!rpcbind_note.empty()) std::fprintf(stderr, "footfalld: %s\n", rpcbind_note.c_str());
  if (!data_root_note.empty()) std::fprintf(stderr, "%s\n", data_root_note.c_str());
  return true;
}

void RpcServer::Stop() {
  if (stop_.exchange(true)) return;
  const int batches = BatchesInProgress();
  if (batches <= 0) return;
  // Only async-signal-safe calls from here: this runs in a signal handler.
  char text[192] = "footfalld: stopping: waiting for ";
  size_t at = std::strlen(text);
  char digits[12];
  int n = 0;
  for (int b = batches; b > 0 && n < 11; b /= 10) digits[n++] = static_cast<char>('0' + b % 10);
  while (n > 0) text[at++] = digits[--n];
  const char* rest = batches == 1 ? " batch in progress" : " batches in progress";
  for (; *rest && at + 1 < sizeof text; ++rest) text[at++] = *rest;
  rest = " (up to --batch-time-limit)\n";
  for (; *rest && at + 1 < sizeof text; ++rest) text[at++] = *rest;
  if (write(STDERR_FILENO, text, at) < 0) {
    // Nothing to do: stderr is gone.
  }
}

void RpcServer::Run() {
  ReadGate& gate = g_loop->gate;
  std::vector<pollfd>& fds = g_loop->fds;
  std::vector<pollfd>& readable = g_loop->readable;
  std::vector<int>& held = g_loop->held;
  auto last_expiry = std::chrono::steady_clock::now();
  // One turn of the loop: waits for sockets and finished loads, serves what is ready, and about
  // once a second expires what has idled. False when the loop must end (poll failed).
  auto turn = [&]() -> bool {
    const int timeout_ms = gate.Prepare(&fds, 250, HeldSockets());
    fds.push_back({g_state->loads->wake_fd(), POLLIN, 0});  // finished loads
    const int ready = poll(fds.data(), fds.size(), timeout_ms);
    if (ready < 0) {
      if (errno == EINTR) return true;
      std::fprintf(stderr, "footfalld: error: poll: %s\n", std::strerror(errno));
      return false;
    }
    const bool loads_done = fds.back().revents != 0;
    fds.pop_back();
    if (loads_done) {
      ReserveAhead(&held, HeldSockets().size());
      held.assign(HeldSockets().begin(), HeldSockets().end());
      FinishLoads();
      for (const int fd : held)
        if (!HeldSockets().count(fd)) gate.Wrote(fd);
    }
    if (ready > (loads_done ? 1 : 0)) {
      // svc_getreq_poll serves the first `count` entries with revents set, reading a request
      // from each: hand it only those whose reply fits.
      gate.Collect(fds, &readable);
      ServeCutLast(&readable);
      if (!readable.empty()) {
        g_partial->Before(readable, listen_fd_);
        svc_getreq_poll(readable.data(), static_cast<int>(readable.size()));
        g_partial->After();
      }
      ReapConnections();
    }
    const auto now = std::chrono::steady_clock::now();
    if (now - last_expiry >= std::chrono::seconds(1)) {
      ExpireIdle();
      g_partial->Expire([](int fd) {
        for (int i = 0; i < svc_max_pollfd; ++i)
          if (svc_pollfd[i].fd == fd) return true;
        return false;
      });
      last_expiry = now;
    }
    return true;
  };
  while (!stop_.load()) {
    try {
      if (!turn()) break;
    } catch (const std::bad_alloc&) {
      // Memory ran out in the loop's own work (its lists of sockets, its log lines): the turn
      // is given up, and the next starts again from the sockets' state. (A request's own
      // failure is its alone: the dispatcher answers it.) Aborting lost every client's terrains.
      try {
        LogLimited("error: out of memory in the main loop: the turn is given up, serving on");
      } catch (const std::bad_alloc&) {
        // The line needs memory too.
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  if (g_state->loads->Abandon()) {
    std::fprintf(stderr, "footfalld: a server-side load was in progress: abandoned\n");
    abandoned_load_ = true;
  }
  std::fprintf(stderr, "footfalld: stopped\n");
}

}  // namespace footfall
