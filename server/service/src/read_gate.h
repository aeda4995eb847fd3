// ReadGate: back-pressure for footfalld's poll loop (internal to footfall::service).
//
// libtirpc's non-blocking transports read a request whenever a socket is readable and then write
// the whole reply, looping on a full socket for up to 2 s: one client that sends requests but
// never reads its replies would hold up everybody else. The gate lets libtirpc read from a
// connection only while the buffers still unsent on its socket (the kernel's own accounting,
// SO_MEMINFO: a client with a small receive window has them cut small, each with its overhead)
// leave room for a largest reply (kMaxReplyBytes) cut the same way, so every reply is written at
// once; a connection without room is polled for POLLOUT only until it drains, and closed when it
// stays without room too long.
#pragma once

#include <poll.h>

#include <chrono>
#include <cstddef>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "footfall.h"
#include "reserve_ahead.h"

namespace footfall {

// [Units: bytes] The largest reply record footfalld sends, from the bounds in footfall.x: a full
// batch reply (FF_MAX_BATCH ff_result of 56 bytes, a status and a length) after the record mark
// and the accepted-reply header (28 bytes). FF_RECENT and FF_LIST replies are smaller.
constexpr size_t kMaxReplyBytes = 28 + 8 + static_cast<size_t>(FF_MAX_BATCH) * 56;
static_assert(kMaxReplyBytes >= 28 + 16 + static_cast<size_t>(FF_MAX_RECENT) * 128,
              "a full FF_RECENT reply is below kMaxReplyBytes");

// [Units: bytes] The free send-buffer space a connection needs before a request is read from it:
// a largest reply and a quarter more, for the kernel's own accounting of queued buffers.
constexpr size_t kReplyRoomBytes = kMaxReplyBytes + kMaxReplyBytes / 4;

// "ADDR:PORT" of the peer of socket `fd`, for log lines, or "an unknown peer".
std::string PeerOf(int fd);

class ReadGate {
 public:
  // `send_buffer` [Units: bytes] is the connections' send buffer as the kernel reports it
  // (getsockopt SO_SNDBUF); `stuck_limit_s` [Units: s] is how long a connection may stay without
  // room before it is closed.
  ReadGate(size_t send_buffer, double stuck_limit_s);

  // Copies libtirpc's svc_pollfd into `fds`, replacing POLLIN by POLLOUT for connections without
  // room for a reply (or by nothing for those the kernel already called writable, rechecked at
  // every call), and shutting down those without room for longer than the limit. Connections in
  // `held` (waiting for a reply held for later, deferred_reply.h) are polled only for errors and
  // for the client closing.
  // Returns the poll timeout [Units: ms]: short while any connection waits, else `idle_ms`.
  int Prepare(std::vector<pollfd>* fds, int idle_ms, const std::set<int>& held);

  // After poll: puts into `readable` the entries of `fds` that libtirpc should serve (ready for
  // reading, or in error), each with its revents, so that svc_getreq_poll(readable, size) reads
  // only from connections whose reply fits.
  void Collect(const std::vector<pollfd>& fds, std::vector<pollfd>* readable);

  // A reply was written to `fd` outside svc_getreq_poll (a held reply): Prepare checks its room
  // again.
  void Wrote(int fd) { Served(fd); }

 private:
  struct Waiting {
    std::chrono::steady_clock::time_point since;  // first seen without room
    bool writable = false;  // the kernel reported POLLOUT, yet there was no room: recheck only
    bool closing = false;   // shut down after the limit: read until libtirpc closes it
  };
  // Marks `fd` served. Allocates only for a socket number above every one reserved for.
  void Served(int fd) {
    if (fd < 0) return;
    GrowForSocket(&served_, fd);
    served_[static_cast<size_t>(fd)] = 1;
  }
  bool WasServed(int fd) const {
    return fd >= 0 && static_cast<size_t>(fd) < served_.size() && served_[static_cast<size_t>(fd)];
  }
  // Shuts `fd` down, so that libtirpc closes it at its next read (a reply written to it fails at
  // once), with a reset rather than a lingering close, and logs it.
  void Close(int fd, double waited_s);

  // Sockets handed to libtirpc (or written to) since the last Prepare: only they, and those
  // waiting, can have less room than before (the unsent bytes of the others only drain), so
  // only they are asked (SIOCOUTQ, a system call each: asking every socket at every turn took
  // the whole core with 2000 idle connections). By socket number, so that a turn of the loop
  // allocates nothing once the numbers in use have been seen: while memory runs out, requests
  // are still read and answered.
  std::vector<char> served_;
  size_t max_queued_;  // [Units: bytes] unsent bytes that still leave kReplyRoomBytes, where
                       // the kernel does not answer SO_MEMINFO
  double stuck_limit_s_;
  std::unordered_map<int, Waiting> waiting_;  // by socket; a new connection starts with room
};

}  // namespace footfall
