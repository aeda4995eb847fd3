// PartialRequests: closes connections stalled in the middle of a request (internal to
// footfall::service).
//
// libtirpc's non-blocking transports keep the part of a request read so far in the
// connection's record buffer, up to FF_MAX_REQUEST_BYTES (about 270 KB): 400 connections that
// each send most of a request and stop held 49 MiB. Which connections hold part of a request is
// told without libtirpc's private state: a connection handed to svc_getreq_poll whose request
// was not dispatched, and to which nothing was written (libtirpc answers a whole request it
// refuses itself, another version or program, with a reply), holds a part of one. A connection
// that holds a part longer than the limit, or the longest-holding one when too many hold parts
// at once, is shut down. Connections idle between requests hold nothing and are kept.
#pragma once

#include <poll.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unordered_map>
#include <vector>

namespace footfall {

class PartialRequests {
 public:
  // `limit_s` [Units: s]: how long a connection may hold part of a request. `max_partial`: how
  // many connections may hold part of a request at once.
  PartialRequests(double limit_s, size_t max_partial);

  // Before svc_getreq_poll(readable): notes what was written so far to each connection in
  // `readable` (the listening socket `listener` excepted). Throws std::bad_alloc when memory
  // runs out, before anything is read.
  void Before(const std::vector<pollfd>& readable, int listener);
  // A request of connection `fd`, one of those handed to Before, reached the dispatcher (call
  // from the dispatch function). Allocates nothing: an exception thrown here would cross
  // libtirpc after it had read the request, which then went unanswered.
  void Dispatched(int fd) noexcept {
    if (fd >= 0 && static_cast<size_t>(fd) < dispatched_.size())
      dispatched_[static_cast<size_t>(fd)] = 1;
  }
  // After svc_getreq_poll: marks the connections that now hold part of a request, and shuts
  // down those past the count.
  void After();
  // Shuts down the connections that have held part of a request past the limit. `open(fd)`
  // says whether libtirpc still serves socket `fd`. Call about once a second.
  template <typename Open>
  void Expire(Open&& open) {
    const auto now = std::chrono::steady_clock::now();
    ReportUnlogged();
    for (auto it = partial_.begin(); it != partial_.end();) {
      if (!open(it->first) || PeerOf(it->first) != it->second.peer) {
        it = partial_.erase(it);  // closed by libtirpc (its number maybe reused)
        continue;
      }
      const double held_s = std::chrono::duration<double>(now - it->second.since).count();
      if (held_s >= limit_s_) {
        char why[96];
        std::snprintf(why, sizeof why, "it sent part of a request and not the rest for %.0f s",
                      held_s);
        Close(it->first, why);
        it = partial_.erase(it);
      } else {
        ++it;
      }
    }
  }
  // Connections holding part of a request now.
  size_t count() const { return partial_.size(); }

 private:
  struct Partial {
    std::chrono::steady_clock::time_point since;  // first seen holding part of this request
    std::string peer;
  };
  static std::string PeerOf(int fd);
  // Shuts `fd` down with a log line: at most kLogBurst lines at once and kLogPerSecond after
  // (a flood of connections would write as many); the others are counted, and said in one
  // line by ReportUnlogged.
  void Close(int fd, const std::string& why);
  void ReportUnlogged();

  double limit_s_;
  size_t max_partial_;
  std::vector<std::pair<int, uint64_t>> handed_;  // connection, bytes written before the round
  std::vector<char> dispatched_;  // by socket number: 1 once a request of it was dispatched
  std::unordered_map<int, Partial> partial_;
  double log_tokens_;
  std::chrono::steady_clock::time_point log_refilled_;
  uint64_t unlogged_ = 0;  // connections closed without a line of their own
};

}  // namespace footfall
