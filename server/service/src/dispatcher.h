// The RPC dispatcher of footfalld (internal to footfall::service).
#pragma once

#include <poll.h>
#include <rpc/rpc.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "footfall/service/terrain_registry.h"
#include "load_queue.h"

namespace footfall {

// A client connection as the dispatcher knows it: an id that is never reused, and the peer
// address it was first seen with (a new connection on a recycled fd has another).
struct Connection {
  uint64_t id = 0;
  std::string peer;
  std::string shown;  // the peer as text ("127.0.0.1:40312"), for the log
  // [Units: steady_clock] When a batch of its was last cut at its time limit (BatchSliceSeconds).
  std::chrono::steady_clock::time_point last_cut{};
};

struct ServiceState {
  TerrainRegistry registry;
  int batch_threads = 1;
  double batch_time_limit_s = 1;          // RpcServerOptions::batch_time_limit_s
  std::map<int, Connection> connections;  // by socket
  uint64_t next_connection = 1;
  std::unique_ptr<LoadQueue> loads;  // server-side loads in progress (set by InstallDispatcher)
};

// [Units: loads] Server-side loads queued or running at once in each lane of the LoadQueue
// (meshes and height maps; point files and upload grids); one more is refused FF_UNAVAILABLE,
// "busy: try again" (the client library waits and tries again). Each connection has at most one:
// it waits for its reply.
constexpr size_t kMaxQueuedLoads = 16;
// Threads per lane: meshes and height maps sampled at once (MaxSamplesPerLoad sizes each for
// two), and point files and upload grids built at once.
constexpr int kLoadWorkers[LoadQueue::kLanes] = {2, 1};

using DispatchFn = void (*)(svc_req*, SVCXPRT*);

// Makes `state` the one the dispatcher serves, and returns the function to register with
// svc_register. One state per process (libtirpc's svc layer is process-global).
DispatchFn InstallDispatcher(ServiceState* state);

// Batches being answered now (0 or 1: one thread serves requests). Async-signal-safe.
int BatchesInProgress();

// Watches the listening transport `listener` (before it serves): the connections libtirpc closes
// at the open descriptor limit, to accept new ones, are logged as such, with the terrains they
// orphan.
void WatchListener(SVCXPRT* listener);

// Forgets the connections libtirpc has closed, ending their uploads and orphaning their
// terrains, and cancels their server-side loads (those waiting leave the queue at once, those
// running stop at their next stage). Call after every svc_getreq_poll, so a closed socket is
// noticed before its number can be reused.
void ReapConnections();

// Replies to the server-side loads that have finished (LoadQueue::wake_fd() is readable),
// adding their terrains. A load whose connection closed meanwhile is dropped, with a log line.
void FinishLoads();

// Moves the sockets of connections whose batch was cut at its time limit since the last call
// to the end of `ready` (the sockets a turn serves, in order), so that the clients waiting
// meanwhile are served before their next request; then forgets them. (svc_getreq_poll serves
// in the order given, which was the sockets' numbers: a client connected after a costly one
// waited two time limits whenever the costly one's next batch came in with its request.)
void ServeCutLast(std::vector<pollfd>* ready);

// Drops idle uploads and frees orphaned terrains left unqueried past their grace period, with a
// log line each. Call about once a second.
void ExpireIdle();

}  // namespace footfall
