#include "read_gate.h"

#include <arpa/inet.h>
#include <linux/sock_diag.h>
#include <linux/sockios.h>
#include <netinet/in.h>
#include <rpc/rpc.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace footfall {
namespace {

// [Units: ms] How often connections without room are checked again while any waits.
constexpr int kRecheckMs = 10;

constexpr short kReadEvents = POLLIN | POLLPRI | POLLRDNORM | POLLRDBAND;

// [Units: bytes] Unsent bytes from which their buffers' overhead per byte is taken as the next
// reply's: below, a few small buffers (a short reply not yet acknowledged) weigh little beside
// the send buffer, whose half holds a largest reply cut however small.
constexpr int kMeasuredFrom = 4096;

// Whether the socket `fd` has room for a largest reply beside the bytes still unsent on it, or
// is not a connection (the listening socket, always read). Measured in the kernel's own
// accounting of the queued buffers (SO_MEMINFO), which is what the send buffer limits: a
// client that makes its receive window small has its bytes queued in small buffers, each with
// its overhead (a 1-byte SO_RCVBUF makes it 2.4 bytes a byte), and the next reply is cut the
// same way. `max_queued` [Units: bytes] is the bound on unsent bytes used where SO_MEMINFO is
// not answered.
bool HasRoom(int fd, size_t max_queued) {
  int queued = 0;
  if (ioctl(fd, SIOCOUTQ, &queued) != 0 || queued <= 0) return true;
  uint32_t memory[SK_MEMINFO_VARS] = {};
  socklen_t length = sizeof memory;
  if (getsockopt(fd, SOL_SOCKET, SO_MEMINFO, memory, &length) != 0 ||
      length <= SK_MEMINFO_WMEM_QUEUED * sizeof(uint32_t))
    return static_cast<size_t>(queued) <= max_queued;
  const double held = memory[SK_MEMINFO_WMEM_QUEUED], limit = memory[SK_MEMINFO_SNDBUF];
  const double per_byte = queued < kMeasuredFrom ? 1.0 : std::max(1.0, held / queued);
  return limit - held >= static_cast<double>(kReplyRoomBytes) * per_byte;
}

}  // namespace

std::string PeerOf(int fd) {
  sockaddr_storage address{};
  socklen_t len = sizeof address;
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&address), &len) != 0) return "an unknown peer";
  char host[INET6_ADDRSTRLEN] = "";
  int port = 0;
  if (address.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&address);
    inet_ntop(AF_INET6, &a->sin6_addr, host, sizeof host);
    port = ntohs(a->sin6_port);
    return std::string("[") + host + "]:" + std::to_string(port);
  }
  const auto* a = reinterpret_cast<const sockaddr_in*>(&address);
  inet_ntop(AF_INET, &a->sin_addr, host, sizeof host);
  port = ntohs(a->sin_port);
  return std::string(host) + ":" + std::to_string(port);
}

ReadGate::ReadGate(size_t send_buffer, double stuck_limit_s)
    : max_queued_(send_buffer > kReplyRoomBytes ? send_buffer - kReplyRoomBytes : 0),
      stuck_limit_s_(stuck_limit_s) {
  GrowForSocket(&served_, static_cast<int>(kLeastReserved) - 1);
}

int ReadGate::Prepare(std::vector<pollfd>* fds, int idle_ms, const std::set<int>& held) {
  ReserveAhead(fds, static_cast<size_t>(svc_max_pollfd) + 1);  // and the caller's one more
  fds->assign(svc_pollfd, svc_pollfd + svc_max_pollfd);
  const auto now = std::chrono::steady_clock::now();
  bool any_waiting = false;
  for (pollfd& p : *fds) {
    p.revents = 0;
    if (p.fd < 0) continue;
    if (held.count(p.fd)) {
      p.events = POLLRDHUP;  // the client closing, which Collect hands to libtirpc
      continue;
    }
    if (!WasServed(p.fd) && !waiting_.count(p.fd)) continue;  // had room, nothing written
    if (HasRoom(p.fd, max_queued_)) {
      waiting_.erase(p.fd);
      continue;
    }
    // try_emplace: nothing is allocated for a connection already waiting (emplace made a node
    // first), so that while memory runs out the turn goes on to read the others.
    Waiting& w = waiting_.try_emplace(p.fd, Waiting{now}).first->second;
    if (w.closing) continue;  // shut down: its replies fail at once, so it may be read
    const double waited_s = std::chrono::duration<double>(now - w.since).count();
    if (waited_s >= stuck_limit_s_) {
      Close(p.fd, waited_s);
      w.closing = true;
      continue;
    }
    p.events = w.writable ? 0 : POLLOUT;
    any_waiting = true;
  }
  served_.assign(served_.size(), 0);
  return any_waiting ? kRecheckMs : idle_ms;
}

void ReadGate::Collect(const std::vector<pollfd>& fds, std::vector<pollfd>* readable) {
  readable->clear();
  ReserveAhead(readable, fds.size());
  for (const pollfd& p : fds) {
    if (p.revents == 0) continue;
    if ((p.events & kReadEvents) || (p.revents & (POLLERR | POLLHUP | POLLNVAL | POLLRDHUP))) {
      readable->push_back(p);
      Served(p.fd);
    } else if (p.revents & POLLOUT) {
      // The kernel calls a socket writable at a third free, which may be less than a reply:
      // stop polling it for POLLOUT (it would spin) and only recheck it in Prepare.
      auto it = waiting_.find(p.fd);
      if (it != waiting_.end()) it->second.writable = true;
    }
  }
}

void ReadGate::Close(int fd, double waited_s) {
  std::fprintf(stderr,
               "footfalld: closing the connection from %s: its replies went unread for %.0f s\n",
               PeerOf(fd).c_str(), waited_s);
  const linger reset{1, 0};
  setsockopt(fd, SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
  shutdown(fd, SHUT_RDWR);
}

}  // namespace footfall
