#include "rpc_connect.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <thread>

#include "footfall.h"

namespace footfall {
namespace {

std::atomic<ResolveFunction> g_resolver{nullptr};
std::atomic<int> g_pending_lookups{0};  // abandoned lookups still running

// One lookup on a helper thread, shared by the thread and the caller waiting for it.
struct Lookup {
  std::mutex mutex;
  std::condition_variable done_cv;
  bool done = false;
  bool abandoned = false;
  int code = EAI_SYSTEM;
  addrinfo* result = nullptr;
};

std::string LookupError(int code) {
  return std::string("cannot resolve host: ") + gai_strerror(code);
}

int ConnectWithTimeout(const addrinfo* a, double timeout_s, std::string* reason) {
  const int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
  if (fd < 0) {
    *reason = std::strerror(errno);
    return -1;
  }
  const int flags = fcntl(fd, F_GETFL, 0);
  fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  int rc = connect(fd, a->ai_addr, a->ai_addrlen);
  if (rc != 0 && errno == EINPROGRESS) {
    // Waited for until the deadline, across signals the caller's handlers take: an interrupted
    // wait read as connected handed libtirpc a connect still in progress, which it waited for
    // with every signal blocked until the kernel gave up (about 130 s).
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(timeout_s));
    pollfd p{fd, POLLOUT, 0};
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      rc = poll(&p, 1, static_cast<int>(std::max<int64_t>(0, left.count())));
      if (rc >= 0 || errno != EINTR) break;
    }
    if (rc < 0) {
      *reason = std::strerror(errno);
      close(fd);
      return -1;
    }
    if (rc == 0) {
      *reason = "connection timed out";
      close(fd);
      return -1;
    }
    int err = 0;
    socklen_t len = sizeof err;
    getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
    rc = err == 0 ? 0 : -1;
    errno = err;
  }
  if (rc != 0) {
    *reason = std::strerror(errno);
    close(fd);
    return -1;
  }
  fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

}  // namespace

bool ResolveBounded(const std::string& host, const std::string& service, const addrinfo& hints,
                    double timeout_s, ResolveFunction resolve, addrinfo** out,
                    std::string* reason) {
  *out = nullptr;
  addrinfo numeric = hints;
  numeric.ai_flags |= AI_NUMERICHOST;
  int code = getaddrinfo(host.c_str(), service.c_str(), &numeric, out);
  if (code != EAI_NONAME) {  // a literal address (or a bad service): no lookup
    if (code != 0) *reason = LookupError(code);
    return code == 0;
  }
  if (g_pending_lookups.load() >= kMaxPendingLookups) {
    *reason = "cannot resolve host: " + std::to_string(kMaxPendingLookups) +
              " earlier lookups are still unanswered";
    return false;
  }
  auto lookup = std::make_shared<Lookup>();
  try {
    std::thread([lookup, host, service, hints, resolve] {
      addrinfo* result = nullptr;
      const int code = resolve(host.c_str(), service.c_str(), &hints, &result);
      std::lock_guard<std::mutex> lock(lookup->mutex);
      if (lookup->abandoned) {
        if (code == 0 && result) freeaddrinfo(result);
        g_pending_lookups.fetch_sub(1);
        return;
      }
      lookup->code = code;
      lookup->result = code == 0 ? result : nullptr;
      lookup->done = true;
      lookup->done_cv.notify_all();
    }).detach();
  } catch (const std::exception&) {
    *reason = "cannot resolve host: cannot start a lookup thread";
    return false;
  }
  std::unique_lock<std::mutex> lock(lookup->mutex);
  const auto wait = std::chrono::duration<double>(std::max(0.0, timeout_s));
  if (!lookup->done_cv.wait_for(lock, wait, [&lookup] { return lookup->done; })) {
    lookup->abandoned = true;
    g_pending_lookups.fetch_add(1);
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", timeout_s);
    *reason =
        std::string("cannot resolve host: no answer from the name lookup within ") + seconds + " s";
    return false;
  }
  if (lookup->code != 0) {
    *reason = LookupError(lookup->code);
    return false;
  }
  *out = lookup->result;
  return true;
}

void SetHostResolver(ResolveFunction resolve) { g_resolver.store(resolve); }

void SetCallTimeout(CLIENT* client, double seconds) {
  timeval timeout;
  timeout.tv_sec = static_cast<time_t>(seconds);
  timeout.tv_usec = static_cast<suseconds_t>((seconds - static_cast<double>(timeout.tv_sec)) * 1e6);
  clnt_control(client, CLSET_TIMEOUT, reinterpret_cast<char*>(&timeout));
}

double BoundedSeconds(double seconds) {
  if (!(seconds > 0)) return 0;  // NaN too
  return std::min(seconds, kMaxTimeoutSeconds);
}

RpcOptions BoundedTimeouts(RpcOptions options) {
  for (double* s : {&options.call_timeout_s, &options.connect_timeout_s, &options.load_timeout_s,
                    &options.busy_timeout_s})
    *s = BoundedSeconds(*s);
  return options;
}

CLIENT* ConnectFootfalld(const RpcOptions& options, std::string* reason) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const ResolveFunction resolver = g_resolver.load();
  if (!ResolveBounded(options.host, std::to_string(options.port), hints, options.call_timeout_s,
                      resolver ? resolver : &getaddrinfo, &found, reason))
    return nullptr;
  CLIENT* client = nullptr;
  *reason = "no address";
  for (addrinfo* a = found; a && !client; a = a->ai_next) {
    const int fd = ConnectWithTimeout(a, options.connect_timeout_s, reason);
    if (fd < 0) continue;
    netbuf address;
    address.maxlen = address.len = static_cast<unsigned>(a->ai_addrlen);
    address.buf = a->ai_addr;
    client = clnt_vc_create(fd, &address, FOOTFALL_PROG, FOOTFALL_V1, FF_MAX_REQUEST_BYTES,
                            FF_MAX_REQUEST_BYTES);
    if (!client) {
      *reason = "cannot create RPC client";
      close(fd);
      continue;
    }
    int close_fd = 1;
    clnt_control(client, CLSET_FD_CLOSE, reinterpret_cast<char*>(&close_fd));
    SetCallTimeout(client, options.call_timeout_s);
  }
  freeaddrinfo(found);
  return client;
}

std::string CallFailureText(clnt_stat status) {
  std::string text = clnt_sperrno(status);
  if (status == RPC_CANTRECV || status == RPC_CANTSEND)
    text +=
        " (the connection closed under the call: footfalld stopped, was killed, or closed "
        "it)";
  else if (status == RPC_SYSTEMERROR)
    text +=
        " (footfalld could not serve the call: it ran out of memory, or the request came on a "
        "connection whose load was still in progress; its log says which)";
  return text;
}

}  // namespace footfall
