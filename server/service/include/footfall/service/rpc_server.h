// RpcServer: footfalld's ONC RPC service over TCP.
//
// One thread drives libtirpc (its svc layer is process-global and single-threaded) over
// non-blocking transports with a bounded record size, so a client that sends half a request
// cannot stall the others; a request is read from a connection only while its socket has room
// for the reply, so one that never reads its replies cannot either (see read_gate.h). Requests are
// decoded, validated and freed by our own dispatcher on every path; no exception escapes a handler.
// One RpcServer per process.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

#include "footfall/service/terrain_registry.h"

namespace footfall {

struct RpcServerOptions {
  std::string listen_host = "127.0.0.1";
  int port = 7407;          // 0 picks a free port (see RpcServer::port())
  std::string data_root;    // confines FF_LOAD; empty refuses server-side loads
  bool use_rpcbind = true;  // register with rpcbind when one is running
  int batch_threads = 1;    // threads per batch query
  // [Units: s] A connection whose unread replies leave no room for another this long is closed.
  double unread_timeout_s = 30;
  // [Units: s] A connection that has sent part of a request and not the rest this long is
  // closed (libtirpc buffers the part, up to about 270 KB a connection); one idle between
  // requests is kept.
  double request_timeout_s = 30;
  // [Units: s] A batch still being answered after this long answers its remaining queries
  // FF_LIMIT_EXCEEDED ("ask again": the client library sends them again in another call), so
  // that costly queries cannot hold the other clients up for longer.
  double batch_time_limit_s = 1;
  RegistryLimits limits;
  // [opt] Called by Start with the bound port, once registered (with rpcbind too) and before
  // the server says it listens (footfalld writes --port-file there): returning false fails
  // Start with the callback's *error, and nothing has said that the server listens.
  std::function<bool(int port, std::string* error)> on_bound;
};

class RpcServer {
 public:
  explicit RpcServer(RpcServerOptions options);
  ~RpcServer();
  RpcServer(const RpcServer&) = delete;
  RpcServer& operator=(const RpcServer&) = delete;

  // Binds, listens, registers, calls options.on_bound, then says it listens. On failure returns
  // false with a message (a registration with rpcbind is withdrawn by the destructor).
  bool Start(std::string* error);
  // The bound port (after Start).
  int port() const { return port_; }
  // After Start succeeded: serves until Stop() is called (from a signal handler or another
  // thread; also before Run, which then returns at once).
  void Run();
  // Async-signal-safe. When a batch is being answered, says (on stderr) that stopping waits for
  // it: a client that did not ask for batches in parts (FF_ASK_AGAIN) gets its whole batch.
  void Stop();
  // After Run: a server-side load was still running, and was left to its thread. The process
  // must end with _exit (the loaders' static data must outlive it).
  bool abandoned_load() const { return abandoned_load_; }

 private:
  RpcServerOptions options_;
  int listen_fd_ = -1;
  int port_ = 0;
  bool every_interface_ = false;  // bound to a wildcard address
  size_t send_buffer_ = 0;        // [Units: bytes] of every connection, as the kernel reports it
  bool registered_rpcbind_ = false;
  bool abandoned_load_ = false;
  std::atomic<bool> stop_{false};
};

}  // namespace footfall
