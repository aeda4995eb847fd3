// The RPC backend: a footfalld client over TCP.
//
// Connections are made by ConnectFootfalld (rpc_connect.h): a bounded connect, and every
// request in one record fragment. A transport failure destroys the client; the next call
// reconnects, and reloads a terrain the server no longer knows (it restarted). A connection the
// server closed while idle is replaced before the next call.
#include <poll.h>
#include <rpc/rpc.h>
#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <map>
#include <thread>

#include "footfall.h"
#include "footfall/client/terrain_session.h"
#include "footfall/rpc/batch_xdr.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"
#include "handle_counter.h"
#include "rpc_connect.h"

namespace footfall {
namespace {

static_assert(static_cast<int>(Status::kOk) == FF_OK, "status mirrors ff_status");
static_assert(static_cast<int>(Status::kNoFoothold) == FF_NO_FOOTHOLD, "");
static_assert(static_cast<int>(Status::kInternalError) == FF_INTERNAL_ERROR, "");

// [Units: s] the longest a destroyed session waits for each unload (RpcOptions::unload_on_close).
constexpr double kCloseTimeout = 2;

ff_vec3 ToWire(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 FromWire(const ff_vec3& v) { return {v.x, v.y, v.z}; }

// A wire status (any 32-bit value) as a Status; values the protocol does not know become
// kInternalError.
Status StatusFromWire(int v) {
  return v >= FF_OK && v <= FF_INTERNAL_ERROR ? static_cast<Status>(v) : Status::kInternalError;
}
Status FromWire(ff_status s) { return StatusFromWire(static_cast<int>(s)); }

// Frees an rpcgen reply when it goes out of scope.
template <typename T>
struct Reply {
  explicit Reply(xdrproc_t proc) : proc(proc) { std::memset(&value, 0, sizeof value); }
  ~Reply() { xdr_free(proc, reinterpret_cast<char*>(&value)); }
  Reply(const Reply&) = delete;
  Reply& operator=(const Reply&) = delete;
  T value;
  xdrproc_t proc;
};

// How a terrain was loaded, so it can be loaded again on a restarted server.
struct TerrainSource {
  enum Kind { kLocalFile, kServerFile, kSamples } kind = kSamples;
  std::string path;
  TerrainLoadOptions options;
  RawSamples samples;
  std::string name;
  uint32_t server_handle = 0;
  bool loaded = false;
};

class RpcSession final : public TerrainSession {
 public:
  explicit RpcSession(const RpcOptions& options) : options_(BoundedTimeouts(options)) {
    std::signal(SIGPIPE, SIG_IGN);
  }
  ~RpcSession() override {
    bool loaded = false;
    for (const auto& entry : terrains_) loaded |= entry.second.loaded;
    if (options_.unload_on_close && loaded && ConnectForUnload(kCloseTimeout)) {
      for (const auto& entry : terrains_)
        if (entry.second.loaded && UnloadOnServer(entry.second) != RPC_SUCCESS) break;  // orphans
    }
    Disconnect();
  }

  Status LoadFile(const std::string& path, const TerrainLoadOptions& options,
                  TerrainHandle* out) override {
    TerrainSource source;
    source.kind = TerrainSource::kLocalFile;
    source.path = path, source.options = options, source.name = path;
    return Register(std::move(source), out);
  }

  Status LoadServerFile(const std::string& path, const TerrainLoadOptions& options,
                        TerrainHandle* out) override {
    if (path.size() > FF_MAX_PATH || path.find('\0') != std::string::npos) {
      return Fail(Status::kInvalidArgument,
                  "a server-side path is at most " + std::to_string(FF_MAX_PATH) +
                      " bytes, without NUL (this one: " + std::to_string(path.size()) + ")");
    }
    TerrainSource source;
    source.kind = TerrainSource::kServerFile;
    source.path = path, source.options = options, source.name = path;
    return Register(std::move(source), out);
  }

  Status LoadSamples(const RawSamples& samples, const std::string& name,
                     TerrainHandle* out) override {
    if (samples.size() == 0)
      return Fail(Status::kInvalidArgument, name + ": no samples (a terrain needs at least one)");
    TerrainSource source;
    source.kind = TerrainSource::kSamples;
    source.samples = samples, source.name = name;
    std::string error;
    const Status status = ValidateAndNormalize(&source.samples, &error);
    if (status != Status::kOk) return Fail(status, name + ": " + error);
    return Register(std::move(source), out);
  }

  Status Info(TerrainHandle terrain, TerrainInfo* out) override {
    return WithTerrain(terrain, [&](uint32_t server) -> Status {
      ff_terrain_args args{server};
      Reply<ff_info_reply> reply(reinterpret_cast<xdrproc_t>(xdr_ff_info_reply));
      Status s = Call(ff_info_1(&args, &reply.value, client_), "info");
      if (s != Status::kOk) return s;
      if (reply.value.status != FF_OK) return ServerFail(reply.value.status, "info");
      const ff_info_reply& r = reply.value;
      out->name = r.name ? r.name : "";
      out->stats = GridStats{};
      out->stats.samples = r.samples;
      out->stats.bounds_min = FromWire(r.bounds_min);
      out->stats.bounds_max = FromWire(r.bounds_max);
      out->stats.cells[0] = r.cells_x, out->stats.cells[1] = r.cells_y;
      out->stats.cells[2] = r.cells_z;
      out->stats.cell_size = r.cell_size;
      out->stats.occupied_cells = r.occupied_cells;
      out->stats.bytes = r.bytes;
      out->stats.spacing = r.spacing;
      return Status::kOk;
    });
  }

  Status Unload(TerrainHandle terrain) override {
    auto it = terrains_.find(terrain);
    if (it == terrains_.end()) return Unknown(terrain);
    // Best effort; through a new connection when footfalld closed the idle one (its terrains
    // are orphans then, which any connection may unload).
    if (it->second.loaded && ConnectForUnload(options_.call_timeout_s)) {
      Call(UnloadOnServer(it->second), "unload");
      if (client_) SetCallTimeout(client_, options_.call_timeout_s);
    }
    terrains_.erase(it);
    return Status::kOk;
  }

  Status Snap(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    return PointBatch(terrain, points, count, out, false);
  }

  Status Normal(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    return PointBatch(terrain, points, count, out, true);
  }

  Status Next(TerrainHandle terrain, const StepQuery* queries, size_t count, double tolerance,
              Foothold* out) override {
    // The terrain first, as the embedded session judges it.
    if (!terrains_.count(terrain)) return Unknown(terrain);
    if (!std::isfinite(tolerance)) return Fail(Status::kInvalidArgument, "tolerance is not finite");
    return BatchCalls(
        terrain, queries, count, out, "next",
        [&](uint32_t server, const StepQuery* q, size_t n, BatchReplyView<Foothold>* reply) {
          NextBatchView<StepQuery> args;
          args.terrain = server;
          args.tolerance = tolerance;
          args.count = args.capacity = static_cast<u_int>(n);
          args.queries = const_cast<StepQuery*>(q);  // only read: encoded
          return CallBatch(FF_NEXT_BATCH, AsXdrProc(XdrNextBatchView<StepQuery>), &args, reply);
        });
  }

  Status Ping() override {
    const Status s = EnsureConnected();
    if (s != Status::kOk) return s;
    char nothing = 0;
    return Call(ff_null_1(nullptr, &nothing, client_), "ping");
  }

  std::string Describe() const override {
    return "rpc " + FormatHostPort(options_.host, options_.port);
  }
  bool InProcess() const override { return false; }

 private:
  Status PointBatch(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out,
                    bool normal) {
    return BatchCalls(
        terrain, points, count, out, normal ? "normal" : "snap",
        [&](uint32_t server, const Vec3* p, size_t n, BatchReplyView<Foothold>* reply) {
          PointBatchView<Vec3> args;
          args.terrain = server;
          args.count = args.capacity = static_cast<u_int>(n);
          args.points = const_cast<Vec3*>(p);  // only read: encoded
          return CallBatch(normal ? FF_NORMAL_BATCH : FF_SNAP_BATCH,
                           AsXdrProc(XdrPointBatchView<Vec3>), &args, reply);
        });
  }

  // Answers `count` queries in calls of at most FF_MAX_BATCH queries, each sent by
  // send(server handle, queries, n, reply) with its answers decoded straight into `out`, then
  // sends again what footfalld left for later (AskAgain).
  template <typename Query, typename SendFn>
  Status BatchCalls(TerrainHandle terrain, const Query* queries, size_t count, Foothold* out,
                    const char* what, SendFn&& send) {
    auto call = [&](const Query* q, size_t n, Foothold* answers) {
      return WithTerrain(terrain, [&](uint32_t server) -> Status {
        BatchReplyView<Foothold> reply;
        reply.results = answers;
        reply.capacity = static_cast<u_int>(n);
        const Status s = Call(send(server, q, n, &reply), what);
        if (s != Status::kOk) return s;
        return TakeBatch(reply, n, answers, what);
      });
    };
    // No queries: nothing to send, but an unknown terrain is said, as the embedded session says
    // it.
    if (count == 0 && !terrains_.count(terrain)) return Unknown(terrain);
    for (size_t begin = 0; begin < count; begin += FF_MAX_BATCH) {
      const size_t n = std::min<size_t>(FF_MAX_BATCH, count - begin);
      Status s = call(queries + begin, n, out + begin);
      if (s == Status::kOk) s = AskAgain(queries + begin, n, out + begin, what, call);
      if (s != Status::kOk) return s;
    }
    return Status::kOk;
  }

  // Asks the connected footfalld to unload a loaded terrain; the call's status (the reply's is
  // not needed: an unload is best effort).
  clnt_stat UnloadOnServer(const TerrainSource& source) {
    ff_terrain_args args{source.server_handle};
    Reply<ff_status_reply> reply(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply));
    return ff_unload_1(&args, &reply.value, client_);
  }

  // Sends again, in calls of their own, the queries footfalld left for later (kLimitExceeded:
  // its batch ran past --batch-time-limit, and it served other clients meanwhile), until each
  // is answered. `call(queries, count, answers)` makes one batch call.
  template <typename Query, typename CallFn>
  Status AskAgain(const Query* queries, size_t n, Foothold* out, const char* what, CallFn&& call) {
    std::vector<size_t> left;
    std::vector<Query> again;
    std::vector<Foothold> answers;
    for (size_t before = n + 1;;) {
      left.clear();
      for (size_t i = 0; i < n; ++i)
        if (out[i].status == Status::kLimitExceeded) left.push_back(i);
      if (left.empty()) return Status::kOk;
      if (left.size() >= before)  // footfalld always answers some: this one answered none
        return Fail(Status::kInternalError,
                    std::string(what) + ": footfalld answered none of the queries asked again");
      before = left.size();
      again.resize(left.size()), answers.resize(left.size());
      for (size_t k = 0; k < left.size(); ++k) again[k] = queries[left[k]];
      const Status s = call(again.data(), again.size(), answers.data());
      if (s != Status::kOk) return s;
      for (size_t k = 0; k < left.size(); ++k) out[left[k]] = answers[k];
    }
  }

  // One batch call with the fast filters; the answers land in reply->results.
  template <typename Args>
  clnt_stat CallBatch(rpcproc_t proc, xdrproc_t encode, Args* args,
                      BatchReplyView<Foothold>* reply) {
    // The client's CLSET_TIMEOUT governs; a zero timeout here would mean "do not wait".
    timeval timeout{};
    timeout.tv_sec = static_cast<time_t>(std::max(1.0, options_.call_timeout_s));
    return clnt_call(client_, proc, encode, reinterpret_cast<char*>(args),
                     AsXdrProc(XdrBatchReplyView<Foothold>), reinterpret_cast<char*>(reply),
                     timeout);
  }

  // Checks a decoded batch reply whose results were written to out[0, n): its status, its
  // count, and each answer's status (an unknown one becomes kInternalError; a failed answer
  // carries no index, point or normal).
  Status TakeBatch(const BatchReplyView<Foothold>& reply, size_t n, Foothold* out,
                   const char* what) {
    if (reply.status != FF_OK) return ServerFail(reply.status, what);
    if (reply.count != n) {
      return Fail(Status::kInternalError, std::string(what) + ": server sent " +
                                              std::to_string(reply.count) + " answers for " +
                                              std::to_string(n) + " queries");
    }
    for (size_t i = 0; i < n; ++i) {
      if (out[i].status == Status::kOk) continue;
      Foothold failed;
      failed.status = StatusFromWire(static_cast<int>(out[i].status));
      out[i] = failed;
    }
    return Status::kOk;
  }

  // Runs fn(server handle) for a session terrain, connecting and (re)loading as needed. If the
  // server no longer knows the terrain (it restarted), loads it again and retries once.
  template <typename Fn>
  Status WithTerrain(TerrainHandle terrain, Fn&& fn) {
    auto it = terrains_.find(terrain);
    if (it == terrains_.end()) return Unknown(terrain);
    for (int attempt = 0; attempt < 2; ++attempt) {
      Status s = EnsureConnected();
      if (s != Status::kOk) return s;
      if (!it->second.loaded) {
        s = Upload(&it->second);
        if (s != Status::kOk) return s;
      }
      s = fn(it->second.server_handle);
      if (s == Status::kUnknownTerrain && attempt == 0) {
        it->second.loaded = false;
        continue;
      }
      return s;
    }
    return Status::kUnknownTerrain;
  }

  Status Register(TerrainSource source, TerrainHandle* out) {
    if (source.kind == TerrainSource::kLocalFile) {
      // Parse on this machine first, so file errors name this machine's file and line.
      std::string error;
      last_file_report_ = TerrainLoadReport{};
      const Status s =
          LoadTerrain(source.path, source.options, &source.samples, &error, &last_file_report_);
      if (s != Status::kOk) return Fail(s, error);
      source.kind = TerrainSource::kSamples;
    }
    Status s = EnsureConnected();
    if (s != Status::kOk) return s;
    s = Upload(&source);
    if (s != Status::kOk) return s;
    const TerrainHandle handle =
        handles_.Next([this](TerrainHandle h) { return terrains_.count(h) != 0; });
    terrains_.emplace(handle, std::move(source));
    *out = handle;
    return Status::kOk;
  }

  Status Upload(TerrainSource* source) {
    source->loaded = false;
    if (source->kind == TerrainSource::kServerFile) {
      const TerrainLoadOptions& o = source->options;
      ff_load_options_args args;
      args.path = const_cast<char*>(source->path.c_str());
      args.separation = o.separation;
      args.finest_default = o.finest_default;
      args.smooth_normals = o.smooth_normals;
      args.crease_angle_deg = o.crease_angle_deg;
      args.seed = o.seed;
      args.up_axis = o.up_axis;
      args.cell_size = o.cell_size;
      args.height_scale = o.height_scale;
      args.max_samples = o.max_samples;
      return BuildCall("load", source, [&](ff_load_reply* reply) {
        return ff_load_options_1(&args, reply, client_);
      });
    }
    const RawSamples& samples = source->samples;
    ff_upload_begin_args begin;
    std::string name(Utf8Prefix(source->name, FF_MAX_NAME));  // whole characters
    begin.name = const_cast<char*>(name.c_str());
    begin.total = samples.size();
    Reply<ff_upload_reply> started(reinterpret_cast<xdrproc_t>(xdr_ff_upload_reply));
    Status s = Call(ff_upload_begin_1(&begin, &started.value, client_), "upload");
    if (s != Status::kOk) return s;
    if (started.value.status != FF_OK)
      return Refused(started.value.status, started.value.message, "upload");
    const uint32_t upload = started.value.upload;
    std::vector<ff_sample> chunk(std::min<size_t>(samples.size(), FF_MAX_CHUNK));
    for (size_t b = 0; b < samples.size(); b += FF_MAX_CHUNK) {
      const size_t n = std::min<size_t>(FF_MAX_CHUNK, samples.size() - b);
      for (size_t i = 0; i < n; ++i)
        chunk[i] = {ToWire(samples.points[b + i]), ToWire(samples.normals[b + i])};
      ff_upload_chunk_args args;
      args.upload = upload;
      args.samples.samples_len = static_cast<u_int>(n);
      args.samples.samples_val = chunk.data();
      Reply<ff_status_reply> reply(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply));
      s = Call(ff_upload_chunk_1(&args, &reply.value, client_), "upload");
      if (s != Status::kOk) return s;
      if (reply.value.status != FF_OK)
        return Refused(reply.value.status, reply.value.message, "upload");
    }
    ff_upload_args finish{upload};
    s = BuildCall("upload", source, [&](ff_load_reply* reply) {
      return ff_upload_finish_1(&finish, reply, client_);
    });
    if (s == Status::kLimitExceeded) DropKeptUpload(upload, samples);
    return s;
  }

  // footfalld keeps an upload whose finish it refused for want of a terrain slot, for a raw
  // client to finish again; this session's caller loads anew instead (Load* has returned), so
  // the upload goes at once rather than holding its samples' budget until --upload-timeout: a
  // chunk past its announced total ends it. The server's advice to finish it again is cut from
  // last_error().
  void DropKeptUpload(uint32_t upload, const RawSamples& samples) {
    const std::string kept = "; upload " + std::to_string(upload) + " is kept";
    const size_t at = last_error_.find(kept);
    if (at == std::string::npos) return;  // not kept (an older server drops it itself)
    last_error_.erase(at);
    ff_sample extra{ToWire(samples.points[0]), ToWire(samples.normals[0])};
    ff_upload_chunk_args args;
    args.upload = upload;
    args.samples.samples_len = 1;
    args.samples.samples_val = &extra;
    Reply<ff_status_reply> reply(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply));
    // Its answer (the upload dropped) changes nothing here; a call that failed reconnects at
    // the next, and the refusal stays what last_error() says.
    const std::string refusal = last_error_;
    Call(ff_upload_chunk_1(&args, &reply.value, client_), "upload");
    last_error_ = refusal;
  }

  // A call whose terrain footfalld builds before it answers (FF_LOAD_OPTIONS, FF_UPLOAD_FINISH):
  // `send(reply)` makes it, waiting up to load_timeout_s (the build may wait its turn behind
  // others'), and again while footfalld answers that it is busy (FF_UNAVAILABLE: its queue is
  // full), for up to busy_timeout_s. On success the terrain is the source's.
  template <typename SendFn>
  Status BuildCall(const char* what, TerrainSource* source, SendFn&& send) {
    const double wait_s = std::max(options_.call_timeout_s, options_.load_timeout_s);
    const auto give_up = std::chrono::steady_clock::now() +
                         std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                             std::chrono::duration<double>(std::max(0.0, options_.busy_timeout_s)));
    double pause_s = 0.05;
    for (;;) {
      Reply<ff_load_reply> reply(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply));
      SetCallTimeout(client_, wait_s);
      const clnt_stat sent = send(&reply.value);
      if (client_) SetCallTimeout(client_, options_.call_timeout_s);
      const Status s = Call(sent, what, wait_s);
      if (s != Status::kOk) return s;
      const std::string message = reply.value.message ? reply.value.message : "";
      if (reply.value.status == FF_UNAVAILABLE) {
        if (std::chrono::steady_clock::now() + std::chrono::duration<double>(pause_s) > give_up) {
          TextStream text;
          text << what << ": footfalld at " << Address() << " stayed busy for "
               << options_.busy_timeout_s << " s (RpcOptions::busy_timeout_s): " << message;
          return Fail(Status::kUnavailable, text.str());
        }
        std::this_thread::sleep_for(std::chrono::duration<double>(pause_s));
        pause_s = std::min(1.0, pause_s * 2);
        continue;
      }
      if (reply.value.status != FF_OK) return Refused(reply.value.status, message.c_str(), what);
      source->server_handle = reply.value.terrain;
      source->loaded = true;
      last_load_report_ = message;
      return Status::kOk;
    }
  }

  // A request footfalld refused with `status`: its `message`, or when it sent none (or an
  // empty one), "WHAT: server answered STATUS".
  Status Refused(ff_status status, const char* message, const char* what) {
    if (!message || !*message) return ServerFail(status, what);
    return Fail(FromWire(status), message);
  }

  Status ServerFail(ff_status status, const char* what) {
    return Fail(FromWire(status),
                std::string(what) + ": server answered " + StatusName(FromWire(status)));
  }

  Status Unknown(TerrainHandle terrain) {
    return Fail(Status::kUnknownTerrain, "no terrain with handle " + std::to_string(terrain));
  }

  // Maps an RPC call result to a status; a transport failure drops the connection. `waited_s`:
  // the call's timeout, for the message (call_timeout_s when negative).
  Status Call(clnt_stat status, const char* what, double waited_s = -1) {
    if (status == RPC_SUCCESS) return Status::kOk;
    std::string reason = CallFailureText(status);
    if (status == RPC_TIMEDOUT) {
      // Loading a large terrain (a mesh resampled finely) can take longer than a query.
      TextStream hint;
      hint << " (no answer within the call timeout of "
           << (waited_s < 0 ? options_.call_timeout_s : waited_s)
           << " s: a busy or hung server, or a terrain that takes longer to load; a longer "
              "timeout may help)";
      reason += hint.str();
    }
    Disconnect();
    return Fail(Status::kUnavailable,
                std::string(what) + ": footfalld at " + Address() + ": " + reason);
  }

  std::string Address() const { return FormatHostPort(options_.host, options_.port); }

  // Whether the server has closed this idle connection: its socket reads an end of file or
  // an error (bytes waiting are no such sign: left to the call).
  bool ClosedByServer() const {
    int fd = -1;
    if (!clnt_control(client_, CLGET_FD, reinterpret_cast<char*>(&fd)) || fd < 0) return false;
    pollfd p{fd, POLLIN | POLLRDHUP, 0};
    if (poll(&p, 1, 0) <= 0) return false;
    if (p.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)) return true;
    char byte;
    return (p.revents & POLLIN) && recv(fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT) == 0;
  }

  void Disconnect() {
    if (client_) {
      clnt_destroy(client_);  // closes the socket (CLSET_FD_CLOSE)
      client_ = nullptr;
      // Terrains stay marked loaded: a server that restarted answers FF_UNKNOWN_TERRAIN for
      // them (its handles start at a random base), and WithTerrain then loads them again.
    }
  }

  // A connection to unload on, each connection attempt and call bounded by `limit_s`, quietly
  // (last_error() is kept): the one there, replaced when footfalld closed it, or a new one after
  // an earlier call failed (footfalld may be back; an unload that asked no one left its
  // terrain an orphan for --orphan-timeout). The call timeout stays at `limit_s`.
  bool ConnectForUnload(double limit_s) {
    const std::string kept = last_error_;
    const RpcOptions saved = options_;
    options_.call_timeout_s = std::min(options_.call_timeout_s, limit_s);
    options_.connect_timeout_s = std::min(options_.connect_timeout_s, limit_s);
    // (A new footfalld that does not answer held a close for the whole call timeout.)
    const bool connected = EnsureConnected() == Status::kOk;
    if (connected) SetCallTimeout(client_, options_.call_timeout_s);
    options_ = saved;
    last_error_ = kept;
    return connected;
  }

  Status EnsureConnected() {
    // A connection footfalld closed while it was idle (at its descriptor limit) is replaced
    // before the call, which would fail at once with "the connection closed under the call"
    // although footfalld is serving.
    const bool closed = client_ && ClosedByServer();
    if (closed) Disconnect();
    if (client_) return Status::kOk;
    std::string reason;
    client_ = ConnectFootfalld(options_, &reason);
    if (!client_) {
      if (closed) {
        reason =
            "the connection closed (footfalld stopped, was killed, or closed it), and "
            "connecting again failed: " +
            reason;
      }
      return Fail(Status::kUnavailable, "footfalld at " + Address() + ": " + reason);
    }
    // This client asks again for batch results left for later (AskAgain). footfalld answers
    // every connection's costly batches in parts now, but earlier ones did so only for
    // connections that said so; one without the procedure answers whole batches.
    Reply<ff_status_reply> reply(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply));
    const clnt_stat asked = ff_ask_again_1(nullptr, &reply.value, client_);
    if (asked != RPC_SUCCESS && asked != RPC_PROCUNAVAIL) return Call(asked, "connect");
    return Status::kOk;
  }

  RpcOptions options_;
  CLIENT* client_ = nullptr;
  HandleCounter handles_;
  std::map<TerrainHandle, TerrainSource> terrains_;
};

}  // namespace

std::unique_ptr<TerrainSession> MakeRpcSession(const RpcOptions& options) {
  return std::make_unique<RpcSession>(options);
}

}  // namespace footfall
