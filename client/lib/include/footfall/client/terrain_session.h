// TerrainSession: one interface for terrain queries, with two backends: the embedded engine
// (in-process, the default) and footfalld over ONC RPC. Both give identical answers.
//
// Batch calls take any number of queries (the RPC backend splits them into protocol-sized
// calls). A call returns kOk when it was carried out; each Foothold then carries its own status
// (kOk, kNoFoothold or kInvalidArgument). Any other return status means the call failed as a
// whole, and last_error() says why in one line. No call throws.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/grid.h"

namespace footfall {

// Names a loaded terrain within a session (and, over RPC, within the server).
using TerrainHandle = uint32_t;

struct TerrainInfo {
  std::string name;
  GridStats stats;  // bytes, occupied cells and grid sizes as the serving engine built them
};

class TerrainSession {
 public:
  virtual ~TerrainSession() = default;
  TerrainSession(const TerrainSession&) = delete;
  TerrainSession& operator=(const TerrainSession&) = delete;

  // Reads a terrain file on this machine (any format of terrain_loader.h) and loads it.
  virtual Status LoadFile(const std::string& path, const TerrainLoadOptions& options,
                          TerrainHandle* out);
  // Loads a file that the serving engine reads itself: a path under footfalld's data root
  // (RPC), or a local path (embedded), with `options` as LoadFile (footfalld also holds meshes
  // and height maps within what is left of its sample budget).
  virtual Status LoadServerFile(const std::string& path, const TerrainLoadOptions& options,
                                TerrainHandle* out) = 0;
  // Loads samples held by the caller; `name` labels the terrain in logs and info.
  virtual Status LoadSamples(const RawSamples& samples, const std::string& name,
                             TerrainHandle* out) = 0;
  virtual Status Info(TerrainHandle terrain, TerrainInfo* out) = 0;
  virtual Status Unload(TerrainHandle terrain) = 0;

  // out[i] answers points[i] / queries[i]; see TerrainGrid for the exact semantics. The
  // arrays must hold `count` items (they may be null when count is 0), as every out pointer of
  // this interface must point at its result: they are not checked (the C ABI checks them).
  virtual Status Snap(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) = 0;
  virtual Status Normal(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) = 0;
  virtual Status Next(TerrainHandle terrain, const StepQuery* queries, size_t count,
                      double tolerance, Foothold* out) = 0;

  // Single-query conveniences over the batch calls.
  Foothold Snap(TerrainHandle terrain, const Vec3& point);
  Foothold Next(TerrainHandle terrain, const StepQuery& query, double tolerance = 0);

  // Whether the serving engine answers: an RPC session connects if needed and makes one call of
  // the RPC NULL procedure, which footfalld answers at once however busy its load queue is
  // (kUnavailable, with the reason, when nothing answers within the call timeout); it loads
  // nothing. The embedded engine always answers.
  virtual Status Ping() { return Status::kOk; }
  // "embedded" or "rpc HOST:PORT".
  virtual std::string Describe() const = 0;
  // True when queries are answered in this process (no round trip per call): callers may then
  // prefer several smaller batches that stay in the caches to one large one, and may call
  // Snap, Normal and Next from several threads at once on a loaded terrain (last_error() is
  // then undefined after a failure). Other sessions serve one call at a time.
  virtual bool InProcess() const = 0;
  // The reason for the last failure, one line: also one a call recovered from (after a
  // footfalld restart, a query that reloaded its terrain succeeds and leaves "server answered
  // unknown_terrain" here), so read it after a call that failed. Destroying a session while
  // another thread calls it is undefined.
  const std::string& last_error() const { return last_error_; }
  // What footfalld said of the last file it loaded for this session ("loaded PATH: N samples",
  // and for a mesh or height map " at separation S", with why when it is coarser than asked);
  // empty in process, where the loader's own report says it.
  const std::string& last_load_report() const { return last_load_report_; }
  // How the last LoadFile read its file on this machine (a mesh's faces turned over, its
  // resampling): empty before one.
  const TerrainLoadReport& last_file_report() const { return last_file_report_; }

 protected:
  TerrainSession() = default;
  Status Fail(Status status, std::string message) {
    last_error_ = std::move(message);
    return status;
  }
  std::string last_error_;
  std::string last_load_report_;
  TerrainLoadReport last_file_report_;
};

// The in-process engine. With `threads` > 1, batches are shared with threads - 1 persistent
// workers started here. Handles are never 0 and never one still loaded: they count up from
// `first_handle` (tests start it near 2^32 - 1) and wrap past the top, skipping those in use.
std::unique_ptr<TerrainSession> MakeEmbeddedSession(int threads = 1,
                                                    TerrainHandle first_handle = 1);

// Timeouts are taken between 0 and 1e6 s: NaN and negative ones as 0, longer ones (infinity
// too) as 1e6 s.
struct RpcOptions {
  std::string host = "127.0.0.1";
  int port = 7407;  // footfalld's default port
  // [Units: s] per call; also bounds the lookup of a host name (a literal address has none)
  double call_timeout_s = 10;
  double connect_timeout_s = 2;  // [Units: s] per connection attempt
  // [Units: s] per load of a server-side file, when longer than call_timeout_s: resampling a
  // large mesh or height map finely takes longer than any query.
  double load_timeout_s = 300;
  // [Units: s] How long a load or upload keeps trying while footfalld answers that it is busy
  // (its queue of loads and upload grids is full: FF_UNAVAILABLE), waiting 0.05 s, then twice as
  // long each time up to 1 s, between tries; past it the call fails kUnavailable, saying so.
  double busy_timeout_s = 120;
  // Destroying the session unloads its terrains from footfalld (best effort, connecting again
  // if a call failed; the connection and each call wait at most 2 s). False leaves them to
  // footfalld as orphans, which any client may query until --orphan-timeout passes without a query
  // (a loader that exits while others query its terrains).
  bool unload_on_close = true;
};

// A client of footfalld. It connects lazily, reports kUnavailable when the server is gone or
// does not answer within the timeouts, and reconnects on the next call once the server is back;
// it then loads its terrains again on the new server (from the same file or the samples it
// kept), so handles stay valid across a server restart. While a call waits for footfalld, the
// calling thread has every signal blocked (libtirpc's clnt_vc_call blocks them for the whole
// call, up to its timeout).
std::unique_ptr<TerrainSession> MakeRpcSession(const RpcOptions& options);

// Parses a host without its port: a name, an IPv4 address, or an IPv6 address bare or in
// brackets ("[::1]" gives "::1"). False for stray brackets, brackets around anything but an
// IPv6 address ("[]", "[localhost]"), or a port ("127.0.0.1:7407").
bool ParseHost(const std::string& text, std::string* host);

// Parses "HOST:PORT" (or ":PORT", "PORT", "[IPV6]:PORT", or a bare IPv6 address at the default
// port, as footfalld's --listen takes it) into options->host and options->port.
Status ParseHostPort(const std::string& text, RpcOptions* options, std::string* error);

// "HOST:PORT" for messages, an IPv6 address in brackets ("[::1]:7407"), as ParseHostPort and
// footfalld's --listen read it back.
std::string FormatHostPort(const std::string& host, int port);

}  // namespace footfall
