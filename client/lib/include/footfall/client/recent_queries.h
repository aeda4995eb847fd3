// RecentQueryFeed: follows the queries a running footfalld answers (its FF_RECENT procedure),
// for live viewers. Each Poll() returns the queries answered since the previous poll.
//
// The server keeps a bounded ring of recent queries (and records only the first queries of a
// large batch), so a slow poller may miss some; `missed()` counts the gaps it noticed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "footfall/client/query_text.h"
#include "footfall/client/terrain_session.h"

namespace footfall {

// One query the server answered.
struct RecentQuery {
  uint64_t sequence = 0;  // the server's running count of recorded queries, from 1
  uint32_t terrain = 0;   // the server's terrain handle (not a session handle)
  QueryOp op = QueryOp::kSnap;
  Vec3 point;            // world space: the query point, or the foot for kNext
  Vec3 direction;        // world space, kNext only: its length is the step length
  double tolerance = 0;  // [Units: wu] kNext only; <= 0 means one step length
  Foothold result;       // the answer the server gave
};

class RecentQueryFeed {
 public:
  // Does not connect; the first Poll() or Start() does. Timeouts come from `options`.
  explicit RecentQueryFeed(const RpcOptions& options);
  ~RecentQueryFeed();
  RecentQueryFeed(const RecentQueryFeed&) = delete;
  RecentQueryFeed& operator=(const RecentQueryFeed&) = delete;

  // Connects and skips everything the server answered before now: later polls return only
  // newer queries. kUnavailable (see last_error()) when the server cannot be reached.
  Status Start();

  // Appends to *out the queries answered since the last poll (at most the protocol's
  // FF_MAX_RECENT per call), oldest first. Reconnects after a transport failure; returns
  // kUnavailable without blocking longer than the connect and call timeouts.
  Status Poll(std::vector<RecentQuery>* out);

  // The sequence of the newest query seen so far (0 before any).
  uint64_t after() const { return after_; }
  // Queries the server recorded but dropped from its ring before they were polled.
  uint64_t missed() const { return missed_; }
  // "HOST:PORT", an IPv6 address in brackets ("[::1]:7407").
  std::string Address() const;
  // Why the last call failed, one line naming the server.
  const std::string& last_error() const { return last_error_; }

 private:
  Status Fetch(std::vector<RecentQuery>* out, uint64_t* latest);
  Status EnsureConnected();
  void Disconnect();
  Status Fail(Status status, std::string message);

  RpcOptions options_;
  struct Connection;
  std::unique_ptr<Connection> connection_;
  uint64_t after_ = 0;
  uint64_t missed_ = 0;
  std::string last_error_;
};

}  // namespace footfall
