// JoinedCalls: several threads, each walking its own characters, share one session's query
// calls: the Snap, Normal and Next calls that the threads wait on together become one call to
// the session per kind (and terrain and tolerance), so a scene of many characters over RPC makes
// about one round trip per round of queries, not one per character.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <vector>

#include "footfall/client/terrain_session.h"

namespace footfall {

class JoinedCalls {
 public:
  // Joins the calls made through its members to `session`, which must outlive this object and
  // its members, and is used by nothing else meanwhile.
  explicit JoinedCalls(TerrainSession& session);
  ~JoinedCalls();
  JoinedCalls(const JoinedCalls&) = delete;
  JoinedCalls& operator=(const JoinedCalls&) = delete;

  // A session for one thread. Its Snap, Normal and Next calls (with queries) wait until every
  // member still alive is waiting on one; then the waiting calls that most of them can share
  // (same kind, terrain and tolerance) are made as one call to the session, and each gets its
  // own answers and that call's status; the others wait on, for the members answered to come
  // back, so that members drift into step. Its other calls go to the session directly, one at a
  // time. Destroying the member leaves. Create every member before any of them queries: a call
  // is made as soon as all members then alive are waiting.
  std::unique_ptr<TerrainSession> Join();

  // Query calls made to the session so far for the members.
  size_t calls() const;

 private:
  class Member;
  struct Request;  // one member's query call, waiting or answered
  // Whether two requests can share one call to the session.
  static bool SameCall(const Request* a, const Request* b);
  // Waits until a call carries *r, making calls while this thread completes the waiting.
  void Ask(Request* r);
  void Leave();
  // Makes one call to the session: the waiting requests that most of them can share. Called
  // with mutex_ held, by the thread whose arrival (or departure) left no member running.
  void RunCall();

  TerrainSession& session_;
  mutable std::mutex mutex_;
  std::condition_variable answered_;
  int members_ = 0;  // alive (joined, not destroyed)
  std::vector<Request*> waiting_;
  std::vector<Request*> call_;  // the requests of the call running
  size_t calls_ = 0;
  std::mutex direct_;  // the session's other calls, one at a time
  std::vector<Vec3> points_;
  std::vector<StepQuery> queries_;
  std::vector<Foothold> answers_;
};

}  // namespace footfall
