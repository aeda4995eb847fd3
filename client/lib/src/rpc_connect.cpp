#include "rpc_connect.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "footfall.h"

namespace footfall {
namespace {

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
    pollfd p{fd, POLLOUT, 0};
    rc = poll(&p, 1, std::max(1, static_cast<int>(timeout_s * 1000)));
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

void SetCallTimeout(CLIENT* client, double seconds) {
  timeval timeout;
  timeout.tv_sec = static_cast<time_t>(seconds);
  timeout.tv_usec = static_cast<suseconds_t>((seconds - static_cast<double>(timeout.tv_sec)) * 1e6);
  clnt_control(client, CLSET_TIMEOUT, reinterpret_cast<char*>(&timeout));
}

CLIENT* ConnectFootfalld(const RpcOptions& options, std::string* reason) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(options.port);
  const int gai = getaddrinfo(options.host.c_str(), port.c_str(), &hints, &found);
  if (gai != 0) {
    *reason = std::string("cannot resolve host: ") + gai_strerror(gai);
    return nullptr;
  }
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

}  // namespace footfall
