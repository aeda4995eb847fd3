#include "partial_requests.h"

#include <linux/tcp.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>

#include "read_gate.h"
#include "reserve_ahead.h"

namespace footfall {
namespace {

// Bytes written to socket `fd` so far, sent or not: it grows with every reply. kUnknown when the
// kernel does not say (the socket is closed).
constexpr uint64_t kUnknown = ~uint64_t{0};
uint64_t BytesWritten(int fd) {
  tcp_info info{};
  socklen_t len = sizeof info;
  if (getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &len) != 0) return kUnknown;
  if (len >= offsetof(tcp_info, tcpi_bytes_retrans))
    return info.tcpi_bytes_sent + info.tcpi_notsent_bytes;
  // Kernels before 4.19: bytes acknowledged and bytes not yet sent (a reply sent but not yet
  // acknowledged is missed: the connection of a request libtirpc refused may then count as
  // holding part of one, until its next request).
  if (len >= offsetof(tcp_info, tcpi_min_rtt))
    return info.tcpi_bytes_acked + info.tcpi_notsent_bytes;
  return kUnknown;
}

}  // namespace

constexpr double kLogBurst = 20;
constexpr double kLogPerSecond = 2;

PartialRequests::PartialRequests(double limit_s, size_t max_partial)
    : limit_s_(limit_s),
      max_partial_(max_partial),
      log_tokens_(kLogBurst),
      log_refilled_(std::chrono::steady_clock::now()) {
  ReserveAhead(&handed_, kLeastReserved);
  GrowForSocket(&dispatched_, static_cast<int>(kLeastReserved) - 1);
}

std::string PartialRequests::PeerOf(int fd) { return footfall::PeerOf(fd); }

void PartialRequests::Before(const std::vector<pollfd>& readable, int listener) {
  handed_.clear();
  ReserveAhead(&handed_, readable.size());
  dispatched_.assign(dispatched_.size(), 0);
  for (const pollfd& p : readable) {
    if (p.fd < 0 || p.fd == listener) continue;
    GrowForSocket(&dispatched_, p.fd);
    handed_.emplace_back(p.fd, BytesWritten(p.fd));
  }
}

void PartialRequests::After() {
  const auto now = std::chrono::steady_clock::now();
  for (const auto& [fd, before] : handed_) {
    if (dispatched_[static_cast<size_t>(fd)]) {
      partial_.erase(fd);  // a whole request: nothing of the next one is read yet
      continue;
    }
    const uint64_t written = BytesWritten(fd);
    if (written == kUnknown || written != before) {
      // Answered by libtirpc itself (a refused whole request), or closed: nothing held.
      partial_.erase(fd);
      continue;
    }
    if (!partial_.count(fd)) partial_.emplace(fd, Partial{now, PeerOf(fd)});
  }
  // Too many at once: the one holding its part longest goes first.
  while (partial_.size() > max_partial_) {
    auto oldest = partial_.begin();
    for (auto it = partial_.begin(); it != partial_.end(); ++it)
      if (it->second.since < oldest->second.since) oldest = it;
    Close(oldest->first, "more connections than " + std::to_string(max_partial_) +
                             " sent part of a request; it waited longest for the rest");
    partial_.erase(oldest);
  }
}

void PartialRequests::Close(int fd, const std::string& why) {
  const auto now = std::chrono::steady_clock::now();
  log_tokens_ = std::min(
      kLogBurst,
      log_tokens_ + kLogPerSecond * std::chrono::duration<double>(now - log_refilled_).count());
  log_refilled_ = now;
  if (log_tokens_ >= 1) {
    log_tokens_ -= 1;
    std::fprintf(stderr, "footfalld: closing the connection from %s: %s\n", PeerOf(fd).c_str(),
                 why.c_str());
  } else {
    ++unlogged_;
  }
  const linger reset{1, 0};
  setsockopt(fd, SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
  shutdown(fd, SHUT_RDWR);
}

void PartialRequests::ReportUnlogged() {
  if (unlogged_ == 0) return;
  std::fprintf(stderr,
               "footfalld: closed %llu more connections that sent part of a request (more than "
               "%g lines at once or %g a second are not written one by one)\n",
               static_cast<unsigned long long>(unlogged_), kLogBurst, kLogPerSecond);
  unlogged_ = 0;
}

}  // namespace footfall
