// footfalld's procedures: decode, validate, answer, free, on every path.
#include "dispatcher.h"

#include <poll.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "deferred_reply.h"
#include "footfall.h"
#include "footfall/rpc/batch_xdr.h"
#include "footfall/terrain/batch_pool.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"
#include "read_gate.h"
#include "reserve_ahead.h"
#include "service_log.h"

namespace footfall {
namespace {

static_assert(static_cast<int>(Status::kOk) == FF_OK, "Status mirrors ff_status");
static_assert(static_cast<int>(Status::kNoFoothold) == FF_NO_FOOTHOLD, "");
static_assert(static_cast<int>(Status::kInvalidArgument) == FF_INVALID_ARGUMENT, "");
static_assert(static_cast<int>(Status::kUnknownTerrain) == FF_UNKNOWN_TERRAIN, "");
static_assert(static_cast<int>(Status::kLimitExceeded) == FF_LIMIT_EXCEEDED, "");
static_assert(static_cast<int>(Status::kIoError) == FF_IO_ERROR, "");
static_assert(static_cast<int>(Status::kParseError) == FF_PARSE_ERROR, "");
static_assert(static_cast<int>(Status::kAccessDenied) == FF_ACCESS_DENIED, "");
static_assert(static_cast<int>(Status::kUnavailable) == FF_UNAVAILABLE, "");
static_assert(static_cast<int>(Status::kInternalError) == FF_INTERNAL_ERROR, "");

// Batches: how many queries of each batch go to the recent-query ring.
constexpr size_t kRecordPerBatch = 16;

ServiceState* g_state = nullptr;
std::unique_ptr<BatchPool> g_pool;

// Request and reply storage, reused across calls (the loop is single-threaded). Batch requests
// are decoded straight into points / steps (FF_MAX_BATCH each), and replies encoded straight from
// answers; reply structs point into this storage.
struct Storage {
  std::string message;
  std::string name;
  std::vector<Vec3> points;
  std::vector<StepQuery> steps;
  std::vector<Foothold> answers;
  std::vector<uint32_t> handles;
  std::vector<ff_recent_query> recent;
  RawSamples chunk;
};
Storage g_storage;

ff_status Wire(Status s) { return static_cast<ff_status>(static_cast<int>(s)); }
Vec3 FromWire(const ff_vec3& v) { return {v.x, v.y, v.z}; }
ff_vec3 ToWire(const Vec3& v) { return {v.x, v.y, v.z}; }

ff_result ToWire(const Foothold& f) {
  ff_result r;
  std::memset(&r, 0, sizeof r);
  r.status = Wire(f.status);
  if (f.status == Status::kOk) {
    r.index = f.index;
    r.point = ToWire(f.point);
    r.normal = ToWire(f.normal);
  }
  return r;
}

char* Message(const std::string& text) {
  g_storage.message = Utf8Shortened(text, FF_MAX_MESSAGE);  // whole characters, reason kept
  return const_cast<char*>(g_storage.message.c_str());
}

// Forgets a client that went away: ends its uploads and orphans its terrains. `how` says how the
// connection ended, for the log.
void DropClient(const Connection& connection,
                const char* how = "the connection that loaded it closed") {
  std::vector<std::string> uploads;
  for (const uint32_t handle : g_state->registry.DropClient(connection.id, &uploads))
    LogLifeLimited("terrain " + std::to_string(handle) + " orphaned: " + how +
                   "; it is freed after " + SecondsText(g_state->registry.limits().orphan_idle_s) +
                   " without queries");
  for (const std::string& upload : uploads)
    LogLifeLimited(upload +
                   " dropped: the connection that began it closed before it finished; its "
                   "samples are freed");
}

// [Units: s] How long a batch of the connection of `transport` may take before its remaining
// queries are answered kLimitExceeded (to be asked again): --batch-time-limit, shared out
// among the connections whose batches were cut within the last two limits. So others wait
// about one limit however many connections send costly batches (each had a whole limit: 12
// such connections held a ping for 12 s).
double BatchSliceSeconds(SVCXPRT* transport) {
  const auto now = std::chrono::steady_clock::now();
  const auto recent = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(2 * g_state->batch_time_limit_s));
  int costly = 1;  // this connection
  for (const auto& [fd, connection] : g_state->connections)
    if (fd != transport->xp_fd && now - connection.last_cut < recent) ++costly;
  return g_state->batch_time_limit_s / costly;
}

// The sockets whose batches were cut at their time limit in this turn (ServeCutLast).
std::vector<int> g_cut_this_turn;

// Notes that a batch of the connection of `transport` was cut at its time limit.
void NoteBatchCut(SVCXPRT* transport) {
  const auto it = g_state->connections.find(transport->xp_fd);
  if (it != g_state->connections.end()) it->second.last_cut = std::chrono::steady_clock::now();
  g_cut_this_turn.push_back(transport->xp_fd);
}

// The connection a request came on, registered on its first request.
const Connection& ConnectionOf(SVCXPRT* transport) {
  const netbuf& address = transport->xp_rtaddr;
  const std::string peer =
      address.buf ? std::string(static_cast<const char*>(address.buf), address.len) : std::string();
  auto it = g_state->connections.find(transport->xp_fd);
  if (it != g_state->connections.end() && it->second.peer != peer) {
    DropClient(it->second);  // the socket number was reused
    g_state->connections.erase(it);
    it = g_state->connections.end();
  }
  if (it == g_state->connections.end()) {
    Connection connection;
    connection.id = g_state->next_connection++;
    connection.peer = peer;
    connection.shown = PeerOf(transport->xp_fd);
    it = g_state->connections.emplace(transport->xp_fd, std::move(connection)).first;
  }
  return it->second;
}

// --- procedures -------------------------------------------------------------------------

// A path decoded with its length kept (the same bytes as xdr_string): a C string would end the
// path at a NUL byte inside it, and load another file than the one named.
struct WirePath {
  char* bytes = nullptr;
  u_int length = 0;
  std::string str() const { return bytes ? std::string(bytes, length) : ""; }
};

bool_t XdrWirePath(XDR* xdrs, WirePath* p) {
  return xdr_bytes(xdrs, &p->bytes, &p->length, FF_MAX_PATH);
}

// ff_load_args.
struct LoadArgs {
  WirePath path;
  double separation = 0;
  TerrainLoadOptions Options() const {
    TerrainLoadOptions o;
    o.separation = separation;
    return o;
  }
};

bool_t XdrLoadArgs(XDR* xdrs, LoadArgs* a) {
  return XdrWirePath(xdrs, &a->path) && xdr_double(xdrs, &a->separation);
}

// ff_load_options_args.
struct LoadOptionsArgs {
  WirePath path;
  double separation = 0, finest_default = 0;
  bool_t smooth_normals = 1;
  double crease_angle_deg = 0;
  u_quad_t seed = 0;
  int up_axis = 0;
  double cell_size = 0, height_scale = 0;
  u_quad_t max_samples = 0;
  TerrainLoadOptions Options() const {
    TerrainLoadOptions o;
    o.separation = separation;
    o.finest_default = finest_default;
    o.smooth_normals = smooth_normals != 0;
    o.crease_angle_deg = crease_angle_deg;
    o.seed = seed;
    // Anything but x, y or z (a character or not) is refused by the loader.
    const bool axis = up_axis == 'x' || up_axis == 'y' || up_axis == 'z';
    o.up_axis = axis ? static_cast<char>(up_axis) : '?';
    o.cell_size = cell_size;
    o.height_scale = height_scale;
    o.max_samples = static_cast<size_t>(max_samples);
    return o;
  }
};

bool_t XdrLoadOptionsArgs(XDR* xdrs, LoadOptionsArgs* a) {
  return XdrWirePath(xdrs, &a->path) && xdr_double(xdrs, &a->separation) &&
         xdr_double(xdrs, &a->finest_default) && xdr_bool(xdrs, &a->smooth_normals) &&
         xdr_double(xdrs, &a->crease_angle_deg) && xdr_u_quad_t(xdrs, &a->seed) &&
         xdr_int(xdrs, &a->up_axis) && xdr_double(xdrs, &a->cell_size) &&
         xdr_double(xdrs, &a->height_scale) && xdr_u_quad_t(xdrs, &a->max_samples);
}

// Logs the uploads the registry dropped for receiving no samples for --upload-timeout.
void LogExpiredUploads() {
  for (const std::string& upload : g_state->registry.TakeExpiredUploads())
    LogLifeLimited(upload + " dropped: no samples for " +
                   SecondsText(g_state->registry.limits().upload_idle_s) +
                   " (--upload-timeout); its samples are freed and its client must upload again");
}

// Logs the orphans the registry freed early to make room for a new terrain or upload.
void LogEvicted() {
  for (const uint32_t handle : g_state->registry.TakeEvicted())
    LogLifeLimited(
        "freed orphaned terrain " + std::to_string(handle) +
        " early, to make room for a new one (at the terrain limit or the sample budget, the "
        "least recently queried orphan goes)");
}

// How a mesh or height map loaded by `load` was resampled, for its log line and reply: " at
// separation S", and when the sample limit made it coarser than the finest the client asked
// (TerrainLoadOptions::finest_default, a character's quarter step), that limit; else "".
std::string ResampledText(const PendingLoad* load) {
  if (!load || load->upload || !(load->report.separation > 0)) return "";
  TextStream text;
  text.precision(4);
  const TerrainLoadOptions& o = load->options;
  text << " at separation " << load->report.separation;
  // The loader aims at the finer of finest_default and the file's own default.
  const double file = load->report.file_separation;
  const double wanted = file > 0 ? std::min(o.finest_default, file) : o.finest_default;
  if (!(o.separation > 0) && wanted > 0 && load->report.separation > 1.001 * wanted)
    text << " (coarser than the " << wanted << " asked: within the limit of " << o.max_samples
         << " samples, no finer)";
  return text.str();
}

// The reply of a load (a file's `path`; `load` [opt] says how it was read) or of an upload
// (`upload`: its name in `path`): its handle, or its error; logged.
void ReplyLoaded(Status s, uint32_t handle, const std::string& path, bool upload,
                 std::string message, ff_load_reply* r, const PendingLoad* load = nullptr) {
  r->status = Wire(s);
  r->terrain = handle;
  if (s == Status::kOk) {
    const GridStats& st = g_state->registry.Find(handle)->grid.stats();
    const std::string resampled = ResampledText(load);
    message =
        upload ? "" : "loaded " + path + ": " + std::to_string(st.samples) + " samples" + resampled;
    LogLoadLimited("loaded terrain " + std::to_string(handle) +
                   (upload ? " '" + path + "' (uploaded)" : " from '" + path + "'") + ": " +
                   std::to_string(st.samples) + " samples" + resampled + ", grid " +
                   std::to_string(st.cells[0]) + "x" + std::to_string(st.cells[1]) + "x" +
                   std::to_string(st.cells[2]) + ClientSuffix());
  } else {
    LogError(upload ? "upload" : "load", s, message);
  }
  r->message = Message(message);
}

// The reply ticket of each load in the LoadQueue.
std::map<PendingLoad*, uint64_t> g_load_tickets;
// The finished loads FinishLoads answers, with room for every load the queue may hold.
std::vector<std::unique_ptr<PendingLoad>> g_finished_loads;

// Withdraws the loads whose connection has closed: those still waiting leave the queue at once
// (their reservations released), those running stop at their next stage. Either way nothing is
// built or kept for a client that has gone.
void CancelAbandonedLoads() {
  for (auto it = g_load_tickets.begin(); it != g_load_tickets.end();) {
    PendingLoad* load = it->first;
    const uint64_t ticket = it->second;
    if (HeldReplyOpen(ticket) || load->cancelled.load()) {
      ++it;
      continue;
    }
    const std::unique_ptr<PendingLoad> withdrawn = g_state->loads->Cancel(load);
    if (!withdrawn) {
      ++it;  // running: FinishLoads drops it when it comes back
      continue;
    }
    // Releases the ticket; nothing is sent, the connection being closed.
    SendHeldReply(ticket, reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), nullptr);
    g_state->registry.DropLoad(withdrawn.get());
    it = g_load_tickets.erase(it);  // before the log line, which may run out of memory
    LogLifeLimited(std::string(withdrawn->upload ? "upload" : "load of") + " '" +
                   withdrawn->relative_path +
                   "' cancelled: its connection closed while it waited its turn");
  }
}

// Queues a prepared load and holds the request's reply for it; false (the load untouched) when
// the queue is full.
bool QueueLoad(SVCXPRT* transport, std::unique_ptr<PendingLoad>* load) {
  // Whatever needs memory comes before the load is queued, and is undone if it runs out: a
  // load queued without its ticket finished with nobody to answer.
  const auto entry = g_load_tickets.emplace(load->get(), 0).first;
  uint64_t ticket = 0;
  bool queued = false;
  try {
    ticket = HoldReply(transport);
    queued = g_state->loads->Submit(load);
  } catch (...) {
    if (ticket) ReleaseHeldReply(ticket);
    g_load_tickets.erase(entry);
    throw;
  }
  if (!queued) {
    ReleaseHeldReply(ticket);
    g_load_tickets.erase(entry);
    return false;
  }
  entry->second = ticket;
  return true;
}

// QueueLoad for a prepared load: one that memory ran out for gives back what it reserved (its
// samples' budget, its terrain slot) before the error goes on.
bool QueueLoadOrDrop(SVCXPRT* transport, std::unique_ptr<PendingLoad>* load) {
  try {
    return QueueLoad(transport, load);
  } catch (...) {
    g_state->registry.DropLoad(load->get());
    throw;
  }
}

std::string QueueFullMessage(LoadQueue::Lane lane) {
  return std::string("footfalld is busy: ") + std::to_string(kMaxQueuedLoads) +
         (lane == LoadQueue::kSampling ? " mesh and height map loads"
                                       : " point file loads and upload grids") +
         " are being built, the most it queues: try again when one has finished";
}

// FF_LOAD and FF_LOAD_OPTIONS: what needs no reading is checked at once (an error is answered
// at once: false); the load is then queued, and its reply held until it is done (true; see
// FinishLoads). Meanwhile the other clients are served.
bool StartLoad(SVCXPRT* transport, const std::string& path, const TerrainLoadOptions& options,
               uint64_t client, ff_load_reply* r) {
  auto load = std::make_unique<PendingLoad>();
  std::string message;
  Status s = g_state->registry.PrepareLoad(path, options, client, load.get(), &message);
  if (s == Status::kOk) {
    if (QueueLoadOrDrop(transport, &load)) return true;
    g_state->registry.DropLoad(load.get());  // its terrain slot goes back: refused as busy
    s = Status::kUnavailable;
    message = QueueFullMessage(LoadQueue::LaneOf(*load));
  }
  ReplyLoaded(s, 0, path, false, message, r);
  return false;
}

void UploadBegin(const ff_upload_begin_args& a, uint64_t client, ff_upload_reply* r) {
  std::string message;
  uint32_t upload = 0;
  const Status s =
      g_state->registry.BeginUpload(a.name ? a.name : "", a.total, client, &upload, &message);
  LogExpiredUploads();
  LogEvicted();
  if (s != Status::kOk) LogError("upload", s, message);
  r->status = Wire(s);
  r->upload = upload;
  r->message = Message(message);
}

void UploadChunk(const ff_upload_chunk_args& a, uint64_t client, ff_status_reply* r) {
  RawSamples& chunk = g_storage.chunk;
  chunk.clear();
  for (u_int i = 0; i < a.samples.samples_len; ++i)
    chunk.push_back(FromWire(a.samples.samples_val[i].point),
                    FromWire(a.samples.samples_val[i].normal));
  std::string message;
  const Status s = g_state->registry.AppendUpload(a.upload, client, chunk, &message);
  if (s != Status::kOk) LogError("upload", s, message);
  r->status = Wire(s);
  r->message = Message(message);
}

// FF_UPLOAD_FINISH: as StartLoad, the grid built off the RPC thread (a grid of millions of
// samples takes a good part of a second).
bool StartUploadFinish(SVCXPRT* transport, const ff_upload_args& a, uint64_t client,
                       ff_load_reply* r) {
  auto load = std::make_unique<PendingLoad>();
  std::string message;
  Status s = Status::kOk;
  if (g_state->loads->Full(LoadQueue::kBuilding)) {
    // Refused before the upload is taken: the client may ask to finish it again, and asking
    // keeps it from being dropped as idle meanwhile.
    g_state->registry.TouchUpload(a.upload, client);
    s = Status::kUnavailable;
    message = QueueFullMessage(LoadQueue::kBuilding);
  } else {
    s = g_state->registry.PrepareFinishUpload(a.upload, client, load.get(), &message);
  }
  if (s == Status::kOk) {
    if (QueueLoadOrDrop(transport, &load)) return true;
    g_state->registry.DropLoad(load.get());  // not reached: the lane was not full
    s = Status::kUnavailable;
    message = QueueFullMessage(LoadQueue::kBuilding);
  }
  ReplyLoaded(s, 0, "", true, message, r);
  return false;
}

// A request naming a terrain footfalld does not hold (never loaded, unloaded, freed, or a
// handle of another server): answered FF_UNKNOWN_TERRAIN, and logged.
void LogUnknownTerrain(const char* proc, uint32_t handle) {
  LogError(proc, Status::kUnknownTerrain,
           "no terrain " + std::to_string(handle) +
               " (never loaded here, unloaded, or freed as an orphan)");
}

void Info(const ff_terrain_args& a, ff_info_reply* r) {
  const LoadedTerrain* t = g_state->registry.Find(a.terrain);
  g_storage.name.clear();
  r->name = const_cast<char*>(g_storage.name.c_str());
  if (!t) {
    LogUnknownTerrain("info", a.terrain);
    r->status = FF_UNKNOWN_TERRAIN;
    return;
  }
  const GridStats& st = t->grid.stats();
  g_storage.name = std::string(Utf8Prefix(t->name, FF_MAX_NAME));  // whole characters
  r->name = const_cast<char*>(g_storage.name.c_str());
  r->status = FF_OK;
  r->samples = st.samples;
  r->bounds_min = ToWire(st.bounds_min);
  r->bounds_max = ToWire(st.bounds_max);
  r->cells_x = st.cells[0], r->cells_y = st.cells[1], r->cells_z = st.cells[2];
  r->cell_size = st.cell_size;
  r->occupied_cells = st.occupied_cells;
  r->bytes = st.bytes;
  r->spacing = st.spacing;
}

void Unload(const ff_terrain_args& a, uint64_t client, ff_status_reply* r) {
  std::string message;
  const Status s = g_state->registry.Unload(a.terrain, client, &message);
  if (s == Status::kOk) LogLoadLimited("unloaded terrain " + std::to_string(a.terrain));
  if (s != Status::kOk) LogError("unload", s, message);
  r->status = Wire(s);
  r->message = Message(s == Status::kOk ? "" : message);
}

void List(ff_list_reply* r) {
  g_storage.handles = g_state->registry.Handles();
  if (g_storage.handles.size() > FF_MAX_TERRAINS) g_storage.handles.resize(FF_MAX_TERRAINS);
  r->status = FF_OK;
  r->terrains.terrains_len = static_cast<u_int>(g_storage.handles.size());
  r->terrains.terrains_val = g_storage.handles.data();
}

void Record(uint32_t terrain, int op, const Vec3& point, const Vec3& direction, double tolerance,
            const Foothold& result) {
  RecentQuery q;
  q.terrain = terrain, q.op = op, q.point = point, q.direction = direction;
  q.tolerance = tolerance, q.result = result;
  g_state->registry.Record(q);
}

void Point(const ff_point_args& a, ff_result* r, int op) {
  const LoadedTerrain* t = g_state->registry.Use(a.terrain);
  if (!t) {
    LogUnknownTerrain(op == FF_OP_SNAP ? "snap" : "normal", a.terrain);
    r->status = FF_UNKNOWN_TERRAIN;
    return;
  }
  const Vec3 q = FromWire(a.point);
  const Foothold f = t->grid.Snap(q);
  *r = ToWire(f);
  Record(a.terrain, op, q, Vec3{}, 0, f);
}

void NextOne(const ff_next_args& a, ff_result* r) {
  const LoadedTerrain* t = g_state->registry.Use(a.terrain);
  if (!t) {
    LogUnknownTerrain("next", a.terrain);
    r->status = FF_UNKNOWN_TERRAIN;
    return;
  }
  const StepQuery q{FromWire(a.query.foot), FromWire(a.query.direction)};
  Foothold f;
  if (std::isfinite(a.tolerance)) {
    f = t->grid.Next(q, a.tolerance);
  } else {
    f.status = Status::kInvalidArgument;  // recorded too, as every refused single query is
  }
  *r = ToWire(f);
  Record(a.terrain, FF_OP_NEXT, q.foot, q.direction, a.tolerance, f);
}

// On the wire a failed answer carries no index, point or normal.
void ClearFailed(Foothold* f) {
  if (f->status == Status::kOk) return;
  Foothold cleared;
  cleared.status = f->status;
  *f = cleared;
}

std::atomic<int> g_batches_in_progress{0};

// Counts a batch in progress while it lives (BatchesInProgress).
struct BatchInProgress {
  BatchInProgress() { ++g_batches_in_progress; }
  ~BatchInProgress() { --g_batches_in_progress; }
  BatchInProgress(const BatchInProgress&) = delete;
  BatchInProgress& operator=(const BatchInProgress&) = delete;
};

// [Units: s] How long a batch answers between looks at the clock, at most: a query that takes
// longer is followed by a look of its own. The time limit is held to within this (or one
// query), while cheap queries are answered in runs long enough that the clock costs nothing.
constexpr double kLimitCheckS = 0.002;

// Answers queries [0, n) of a batch into g_storage.answers on the batch threads; `answer(b, e)`
// fills answers [b, e). Queries taken after `limit_s` seconds are answered kLimitExceeded, to be
// asked again (the first always is answered: every call makes progress). True if any was; the
// log line saying so names the client `peer`.
template <typename Fn>
bool RunBatch(size_t n, BatchReplyView<Foothold>* r, double limit_s, const std::string& peer,
              Fn&& answer) {
  Foothold* answers = g_storage.answers.data();
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(limit_s));
  const auto check_every = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(std::min(kLimitCheckS, limit_s / 8)));
  std::atomic<size_t> late{0};
  const BatchInProgress counted;
  g_pool->Run(n, BatchPool::kQueryChunk, [&](size_t begin, size_t end) {
    // One call may cover the whole batch (one thread). Queries are answered in runs sized to
    // the time they take: a run starts at one query and doubles while it takes under half of
    // check_every, so costly queries (a `next` of huge tolerance on a large terrain) see the
    // clock after each one, and cheap ones every kQueryChunk.
    size_t run = 1;
    auto now = Clock::now();
    for (size_t b = begin; b < end;) {
      if (b > 0 && now > deadline) {
        for (size_t i = b; i < end; ++i)
          answers[i] = Foothold{}, answers[i].status = Status::kLimitExceeded;
        late += end - b;
        return;
      }
      const size_t e = std::min(end, b + run);
      answer(b, e, answers);
      for (size_t i = b; i < e; ++i) ClearFailed(&answers[i]);
      const auto then = now;
      now = Clock::now();
      if (now - then < check_every / 2 && run < BatchPool::kQueryChunk)
        run *= 2;
      else if (now - then > check_every && run > 1)
        run /= 2;
      b = e;
    }
  });
  if (late > 0)
    LogLimited("batch of " + std::to_string(n) + " queries past its time limit (" +
               SecondsText(limit_s) +
               (limit_s < g_state->batch_time_limit_s ? ", --batch-time-limit shared with other "
                                                        "connections sending costly batches"
                                                      : "") +
               "): " + std::to_string(late.load()) +
               " answered limit_exceeded, to be asked again (client " + peer + ")");
  r->status = FF_OK;
  r->count = r->capacity = static_cast<u_int>(n);
  r->results = answers;
  return late > 0;
}

// A snap or normal batch, answered within `limit_s` seconds (RunBatch). True if cut.
bool PointBatch(const PointBatchView<Vec3>& a, BatchReplyView<Foothold>* r, int op, double limit_s,
                const std::string& peer) {
  const LoadedTerrain* t = g_state->registry.Use(a.terrain);
  if (!t) {
    LogUnknownTerrain(op == FF_OP_SNAP ? "snap batch" : "normal batch", a.terrain);
    r->status = FF_UNKNOWN_TERRAIN;
    return false;
  }
  const size_t n = a.count;
  const Vec3* points = a.points;
  const bool cut = RunBatch(n, r, limit_s, peer, [&](size_t b, size_t e, Foothold* out) {
    t->grid.SnapBatch(points + b, e - b, out + b);
  });
  for (size_t i = 0; i < n && i < kRecordPerBatch; ++i)
    Record(a.terrain, op, points[i], Vec3{}, 0, r->results[i]);
  return cut;
}

// A next batch, answered within `limit_s` seconds (RunBatch). True if cut.
bool NextBatch(const NextBatchView<StepQuery>& a, BatchReplyView<Foothold>* r, double limit_s,
               const std::string& peer) {
  const LoadedTerrain* t = g_state->registry.Use(a.terrain);
  if (!t) {
    LogUnknownTerrain("next batch", a.terrain);
    r->status = FF_UNKNOWN_TERRAIN;
    return false;
  }
  if (!std::isfinite(a.tolerance)) {
    r->status = FF_INVALID_ARGUMENT;
    return false;
  }
  const size_t n = a.count;
  const StepQuery* steps = a.queries;
  const double tolerance = a.tolerance;
  const bool cut = RunBatch(n, r, limit_s, peer, [&](size_t b, size_t e, Foothold* out) {
    t->grid.NextBatch(steps + b, e - b, tolerance, out + b);
  });
  for (size_t i = 0; i < n && i < kRecordPerBatch; ++i)
    Record(a.terrain, FF_OP_NEXT, steps[i].foot, steps[i].direction, tolerance, r->results[i]);
  return cut;
}

void Recent(const ff_recent_args& a, ff_recent_reply* r) {
  uint64_t latest = 0;
  const std::vector<RecentQuery> found =
      g_state->registry.RecentAfter(a.after, FF_MAX_RECENT, &latest);
  g_storage.recent.resize(found.size());
  for (size_t i = 0; i < found.size(); ++i) {
    ff_recent_query& w = g_storage.recent[i];
    const RecentQuery& q = found[i];
    w.sequence = q.sequence;
    w.terrain = q.terrain;
    w.op = static_cast<ff_op>(q.op);
    w.point = ToWire(q.point);
    w.direction = ToWire(q.direction);
    w.tolerance = q.tolerance;
    w.result = ToWire(q.result);
  }
  r->status = FF_OK;
  r->latest = latest;
  r->queries.queries_len = static_cast<u_int>(found.size());
  r->queries.queries_val = g_storage.recent.data();
}

// Logs the line `make()` builds, once the request has been answered: when memory runs out the
// line is lost, rather than the exception reaching Dispatch, which would answer again.
template <typename Make>
void LogAnswered(Make&& make) noexcept {
  try {
    Log(make());
  } catch (...) {
  }
}

// Decodes the arguments into `args` (set up by the caller: empty, or pointing at storage),
// runs the handler, replies and frees the arguments, whatever happens. Every reply type starts
// with its ff_status, which an exception turns into an error. A handler that returns true has
// held its reply (HoldReply) and sends it later.
template <typename Args, typename Res, typename Fn>
void ServeWith(SVCXPRT* transport, xdrproc_t decode, Args& args, xdrproc_t encode, const char* proc,
               Fn&& fn) {
  if (!svc_getargs(transport, decode, reinterpret_cast<char*>(&args))) {
    svc_freeargs(transport, decode, reinterpret_cast<char*>(&args));
    svcerr_decode(transport);
    LogAnswered([&] {
      return std::string("error: ") + proc + ": malformed request from " +
             PeerOf(transport->xp_fd) +
             " rejected (its arguments do not decode: more items than the protocol allows or "
             "than were sent, a string too long, a value out of its type, or a request sent in "
             "more than one record fragment: a client must send each in one, with a send size "
             "of at least FF_MAX_REQUEST_BYTES)";
    });
    return;
  }
  Res res{};
  // What went wrong, copied without allocating (an exception's own text dies with its handler),
  // and the reply's message saying it.
  char failure[128] = "";
  char failure_message[192] = "";
  bool held = false;
  try {
    if constexpr (std::is_same_v<std::invoke_result_t<Fn&, Args&, Res*>, bool>)
      held = fn(args, &res);
    else
      fn(args, &res);
  } catch (const std::bad_alloc&) {
    std::snprintf(failure, sizeof failure, "%s", "out of memory");
  } catch (const std::exception& e) {
    std::snprintf(failure, sizeof failure, "%s", e.what());
  } catch (...) {
    std::snprintf(failure, sizeof failure, "%s", "unknown exception");
  }
  if (held) {
    svc_freeargs(transport, decode, reinterpret_cast<char*>(&args));
    return;
  }
  if (failure[0]) {
    try {
      Log(std::string("error: ") + proc + ": " + failure);
    } catch (const std::bad_alloc&) {
      // The reply matters more than its log line: a throw here left the client unanswered.
    }
    res = Res{};
    *reinterpret_cast<ff_status*>(&res) = FF_INTERNAL_ERROR;
    std::snprintf(failure_message, sizeof failure_message, "footfalld failed serving %s: %s", proc,
                  failure);
    if constexpr (std::is_same_v<Res, ff_status_reply> || std::is_same_v<Res, ff_load_reply> ||
                  std::is_same_v<Res, ff_upload_reply>)
      res.message = failure_message;
  }
  // Strings may not be NULL on the wire: give unset ones an empty value.
  if constexpr (std::is_same_v<Res, ff_status_reply> || std::is_same_v<Res, ff_load_reply> ||
                std::is_same_v<Res, ff_upload_reply>) {
    if (!res.message) res.message = const_cast<char*>("");
  }
  if constexpr (std::is_same_v<Res, ff_info_reply>) {
    if (!res.name) res.name = const_cast<char*>("");
  }
  if (!svc_sendreply(transport, encode, reinterpret_cast<char*>(&res)))
    LogAnswered([&] { return std::string("error: ") + proc + ": reply could not be sent"; });
  svc_freeargs(transport, decode, reinterpret_cast<char*>(&args));
}

// ServeWith for rpcgen argument types, decoded into zeroed structs.
template <typename Args, typename Res, typename Fn>
void Serve(SVCXPRT* transport, xdrproc_t decode, xdrproc_t encode, const char* proc, Fn&& fn) {
  Args args{};
  ServeWith<Args, Res>(transport, decode, args, encode, proc, std::forward<Fn>(fn));
}

#define FF_XDR(name) reinterpret_cast<xdrproc_t>(xdr_##name)
// xdr_void takes no arguments in libtirpc's declaration; go through void* to cast it.
#define FF_XDR_VOID reinterpret_cast<xdrproc_t>(reinterpret_cast<void*>(xdr_void))

void DispatchRequest(svc_req* request, SVCXPRT* transport) {
  if (ReplyHeld(transport)) {
    // Only a client that sent another request before its load's reply, then closed, gets here
    // (a held connection is read only once in error).
    svcerr_systemerr(transport);
    LogAnswered([] {
      return std::string(
          "error: a request sent while the connection's load was in progress: "
          "refused");
    });
    return;
  }
  const Connection& connection = ConnectionOf(transport);
  const uint64_t client = connection.id;
  const LogClientScope named(&connection.shown);
  switch (request->rq_proc) {
    case FF_NULL:
      svc_sendreply(transport, FF_XDR_VOID, nullptr);
      return;
    case FF_LOAD:
      return Serve<LoadArgs, ff_load_reply>(
          transport, AsXdrProc(XdrLoadArgs), FF_XDR(ff_load_reply), "load",
          [transport, client](const LoadArgs& a, ff_load_reply* r) {
            return StartLoad(transport, a.path.str(), a.Options(), client, r);
          });
    case FF_LOAD_OPTIONS:
      return Serve<LoadOptionsArgs, ff_load_reply>(
          transport, AsXdrProc(XdrLoadOptionsArgs), FF_XDR(ff_load_reply), "load",
          [transport, client](const LoadOptionsArgs& a, ff_load_reply* r) {
            return StartLoad(transport, a.path.str(), a.Options(), client, r);
          });
    case FF_UPLOAD_BEGIN:
      return Serve<ff_upload_begin_args, ff_upload_reply>(
          transport, FF_XDR(ff_upload_begin_args), FF_XDR(ff_upload_reply), "upload",
          [client](const ff_upload_begin_args& a, ff_upload_reply* r) {
            UploadBegin(a, client, r);
          });
    case FF_UPLOAD_CHUNK:
      return Serve<ff_upload_chunk_args, ff_status_reply>(
          transport, FF_XDR(ff_upload_chunk_args), FF_XDR(ff_status_reply), "upload",
          [client](const ff_upload_chunk_args& a, ff_status_reply* r) {
            UploadChunk(a, client, r);
          });
    case FF_UPLOAD_FINISH:
      return Serve<ff_upload_args, ff_load_reply>(
          transport, FF_XDR(ff_upload_args), FF_XDR(ff_load_reply), "upload",
          [transport, client](const ff_upload_args& a, ff_load_reply* r) {
            return StartUploadFinish(transport, a, client, r);
          });
    case FF_INFO:
      return Serve<ff_terrain_args, ff_info_reply>(transport, FF_XDR(ff_terrain_args),
                                                   FF_XDR(ff_info_reply), "info", Info);
    case FF_UNLOAD:
      return Serve<ff_terrain_args, ff_status_reply>(
          transport, FF_XDR(ff_terrain_args), FF_XDR(ff_status_reply), "unload",
          [client](const ff_terrain_args& a, ff_status_reply* r) { Unload(a, client, r); });
    case FF_LIST: {
      struct Empty {
        int unused;
      };
      return Serve<Empty, ff_list_reply>(transport, FF_XDR_VOID, FF_XDR(ff_list_reply), "list",
                                         [](const Empty&, ff_list_reply* r) { List(r); });
    }
    case FF_SNAP:
    case FF_NORMAL: {
      const int op = request->rq_proc == FF_SNAP ? FF_OP_SNAP : FF_OP_NORMAL;
      return Serve<ff_point_args, ff_result>(
          transport, FF_XDR(ff_point_args), FF_XDR(ff_result),
          request->rq_proc == FF_SNAP ? "snap" : "normal",
          [op](const ff_point_args& a, ff_result* r) { Point(a, r, op); });
    }
    case FF_NEXT:
      return Serve<ff_next_args, ff_result>(transport, FF_XDR(ff_next_args), FF_XDR(ff_result),
                                            "next", NextOne);
    case FF_SNAP_BATCH:
    case FF_NORMAL_BATCH: {
      const int op = request->rq_proc == FF_SNAP_BATCH ? FF_OP_SNAP : FF_OP_NORMAL;
      PointBatchView<Vec3> args;
      args.points = g_storage.points.data();
      args.capacity = FF_MAX_BATCH;
      return ServeWith<PointBatchView<Vec3>, BatchReplyView<Foothold>>(
          transport, AsXdrProc(XdrPointBatchView<Vec3>), args,
          AsXdrProc(XdrBatchReplyView<Foothold>),
          request->rq_proc == FF_SNAP_BATCH ? "snap batch" : "normal batch",
          [op, transport](const PointBatchView<Vec3>& a, BatchReplyView<Foothold>* r) {
            if (PointBatch(a, r, op, BatchSliceSeconds(transport), ConnectionOf(transport).shown))
              NoteBatchCut(transport);
          });
    }
    case FF_NEXT_BATCH: {
      NextBatchView<StepQuery> args;
      args.queries = g_storage.steps.data();
      args.capacity = FF_MAX_BATCH;
      return ServeWith<NextBatchView<StepQuery>, BatchReplyView<Foothold>>(
          transport, AsXdrProc(XdrNextBatchView<StepQuery>), args,
          AsXdrProc(XdrBatchReplyView<Foothold>), "next batch",
          [transport](const NextBatchView<StepQuery>& a, BatchReplyView<Foothold>* r) {
            if (NextBatch(a, r, BatchSliceSeconds(transport), ConnectionOf(transport).shown))
              NoteBatchCut(transport);
          });
    }
    case FF_ASK_AGAIN: {
      struct Empty {
        int unused;
      };
      return Serve<Empty, ff_status_reply>(
          transport, FF_XDR_VOID, FF_XDR(ff_status_reply), "ask again",
          // Every connection's batches are answered in parts now: kept for clients that ask.
          [](const Empty&, ff_status_reply* r) {
            r->status = FF_OK;
            r->message = Message("");
          });
    }
    case FF_RECENT:
      return Serve<ff_recent_args, ff_recent_reply>(transport, FF_XDR(ff_recent_args),
                                                    FF_XDR(ff_recent_reply), "recent", Recent);
    default:
      svcerr_noproc(transport);
      LogAnswered([&] {
        return "error: unknown procedure " + std::to_string(request->rq_proc) + " of version " +
               std::to_string(FOOTFALL_V1) + " from " + PeerOf(transport->xp_fd) +
               " rejected (PROC_UNAVAIL: a client built from another rpc/footfall.x?)";
      });
      return;
  }
}

// --- connections closed at the descriptor limit -------------------------------------------

using TransportOps = std::remove_const_t<std::remove_pointer_t<decltype(SVCXPRT::xp_ops)>>;
const TransportOps* g_listener_original = nullptr;
TransportOps g_listener_watched{};
std::map<int, std::string> g_peers;  // by socket: the peer of each connection, taken at accept
uint64_t g_closed_at_limit = 0;      // connections libtirpc closed at the descriptor limit

// The listening transport's receive: libtirpc's accept, watched. When accept fails for want of a
// descriptor, libtirpc closes the least recently active connection (its idle sweep), inside this
// call and without a word: the sockets open before and gone after are those, and are logged
// (with the terrains they orphan) rather than taken for clients that went away.
std::vector<char> g_open_before, g_open_after;  // by socket number, before and after an accept

template <typename Mark>
void NoteAcceptedAndClosed(const Mark& mark);

bool_t ListenerReceived(SVCXPRT* listener, rpc_msg* message) {
  auto mark = [](std::vector<char>* open) {
    open->assign(open->size(), 0);
    for (int i = 0; i < svc_max_pollfd; ++i) {
      const int fd = svc_pollfd[i].fd;
      if (fd < 0) continue;
      if (static_cast<size_t>(fd) >= open->size()) open->resize(static_cast<size_t>(fd) + 1, 0);
      (*open)[static_cast<size_t>(fd)] = 1;
    }
  };
  // No exception crosses into libtirpc: when memory runs out for the watch, the accept goes on
  // unwatched (a connection closed at the limit meanwhile is then forgotten by ReapConnections).
  try {
    mark(&g_open_before);
  } catch (const std::bad_alloc&) {
    return g_listener_original->xp_recv(listener, message);
  }
  const bool_t result = g_listener_original->xp_recv(listener, message);
  try {
    NoteAcceptedAndClosed(mark);
  } catch (const std::bad_alloc&) {
  }
  return result;
}

// The sockets libtirpc opened (accepted) and closed (its idle sweep) within an accept, from
// ListenerReceived's marks before it and after it.
template <typename Mark>
void NoteAcceptedAndClosed(const Mark& mark) {
  mark(&g_open_after);
  g_open_after.resize(std::max(g_open_after.size(), g_open_before.size()), 0);
  for (size_t fd = 0; fd < g_open_after.size(); ++fd) {
    const bool was = fd < g_open_before.size() && g_open_before[fd];
    if (!was && g_open_after[fd]) g_peers[static_cast<int>(fd)] = PeerOf(static_cast<int>(fd));
    if (!was || g_open_after[fd]) continue;
    // Closed inside accept: the idle sweep.
    ++g_closed_at_limit;
    const auto peer = g_peers.find(static_cast<int>(fd));
    rlimit files{};
    getrlimit(RLIMIT_NOFILE, &files);
    Log("at the open descriptor limit (" + std::to_string(files.rlim_cur) +
        "): closed the least recently active connection, from " +
        (peer != g_peers.end() ? peer->second : std::string("an unknown peer")) +
        ", to take new ones (" + std::to_string(g_closed_at_limit) +
        " closed this way so far; raise the limit, ulimit -n, to keep more clients)");
    if (peer != g_peers.end()) g_peers.erase(peer);
    const auto it = g_state->connections.find(static_cast<int>(fd));
    if (it != g_state->connections.end()) {
      DropClient(it->second,
                 "footfalld closed the connection that loaded it, the least recently active, at "
                 "the open descriptor limit");
      g_state->connections.erase(it);
    }
  }
}

}  // namespace

int BatchesInProgress() { return g_batches_in_progress.load(); }

void WatchListener(SVCXPRT* listener) {
  g_listener_original = listener->xp_ops;
  g_listener_watched = *listener->xp_ops;
  g_listener_watched.xp_recv = ListenerReceived;
  listener->xp_ops = &g_listener_watched;
}

void ReapConnections() {
  if (!g_state) return;
  if (!g_load_tickets.empty()) CancelAbandonedLoads();
  if (g_state->connections.empty()) return;
  // Which sockets are open, by number (one pass, no allocation once grown: this runs after
  // every request, with thousands of connections open).
  static std::vector<char> open;
  open.assign(open.size(), 0);
  for (int i = 0; i < svc_max_pollfd; ++i) {
    const int fd = svc_pollfd[i].fd;
    if (fd < 0) continue;
    GrowForSocket(&open, fd);
    open[static_cast<size_t>(fd)] = 1;
  }
  for (auto it = g_state->connections.begin(); it != g_state->connections.end();) {
    if (static_cast<size_t>(it->first) < open.size() && open[static_cast<size_t>(it->first)]) {
      ++it;
      continue;
    }
    DropClient(it->second);
    it = g_state->connections.erase(it);
  }
}

namespace {

// Answers the finished load `load` on its held reply `ticket`: adds its terrain (*handle, once
// added) and replies, or drops it when its connection has closed.
void AnswerLoad(PendingLoad* load, uint64_t ticket, uint32_t* handle) {
  if (!HeldReplyOpen(ticket)) {
    SendHeldReply(ticket, FF_XDR(ff_load_reply), nullptr);  // releases the ticket
    g_state->registry.DropLoad(load);
    LogLifeLimited(std::string(load->upload ? "upload" : "load of") + " '" + load->relative_path +
                   "' dropped: its connection closed before it finished");
    return;
  }
  ff_load_reply r{};
  std::string message;
  const std::string* owner = nullptr;
  for (const auto& connection : g_state->connections)
    if (connection.second.id == load->owner) owner = &connection.second.shown;
  const LogClientScope named(owner);
  const Status s = g_state->registry.FinishLoad(load, handle, &message);
  LogEvicted();
  ReplyLoaded(s, *handle, load->relative_path, load->upload, message, &r, load);
  if (!SendHeldReply(ticket, FF_XDR(ff_load_reply), &r))
    Log(std::string("error: ") + (load->upload ? "upload" : "load") + ": reply could not be sent");
}

}  // namespace

void FinishLoads() {
  if (!g_state) return;
  g_state->loads->TakeFinished(&g_finished_loads);
  for (const std::unique_ptr<PendingLoad>& load : g_finished_loads) {
    const auto it = g_load_tickets.find(load.get());
    if (it == g_load_tickets.end()) continue;
    const uint64_t ticket = it->second;
    g_load_tickets.erase(it);
    uint32_t handle = 0;
    try {
      AnswerLoad(load.get(), ticket, &handle);
    } catch (const std::bad_alloc&) {
      // Memory ran out on the way: the client is answered all the same (no reply at all held
      // it until its timeout), with its terrain if it was added. (A reply already sent is not
      // sent again: its ticket is gone.)
      static char no_message[] = "";
      static char out_of_memory[] = "footfalld ran out of memory finishing the load: try again";
      ff_load_reply r{};
      r.terrain = handle;
      r.status = handle ? FF_OK : FF_LIMIT_EXCEEDED;
      r.message = handle ? no_message : out_of_memory;
      if (!handle) g_state->registry.DropLoad(load.get());
      SendHeldReply(ticket, FF_XDR(ff_load_reply), &r);
    }
  }
  g_finished_loads.clear();  // (keeps its room for the next turn)
}

void ServeCutLast(std::vector<pollfd>* ready) {
  if (g_cut_this_turn.empty()) return;
  std::stable_partition(ready->begin(), ready->end(), [](const pollfd& p) {
    return std::find(g_cut_this_turn.begin(), g_cut_this_turn.end(), p.fd) == g_cut_this_turn.end();
  });
  g_cut_this_turn.clear();
}

void ExpireIdle() {
  ReportUnwrittenErrors();
  if (!g_state) return;
  g_state->registry.ExpireUploads();
  LogExpiredUploads();
  for (const uint32_t handle : g_state->registry.ExpireOrphans())
    LogLifeLimited("freed orphaned terrain " + std::to_string(handle) + " after " +
                   SecondsText(g_state->registry.limits().orphan_idle_s) + " without queries");
}

namespace {

// libtirpc's entry point: no exception crosses into its C code. What throws before a reply is
// sent (memory running out as the connection is registered) is answered SYSTEM_ERR, and logged
// when memory allows: the client is told at once, not left waiting for its timeout.
void Dispatch(svc_req* request, SVCXPRT* transport) {
  const char* why = "an unknown exception";
  try {
    DispatchRequest(request, transport);
    return;
  } catch (const std::bad_alloc&) {
    why = "out of memory";
  } catch (...) {
  }
  svcerr_systemerr(transport);
  LogAnswered([why, transport] {
    return std::string("error: a request from ") + PeerOf(transport->xp_fd) +
           " could not be served (" + why + "): answered SYSTEM_ERR";
  });
}

}  // namespace

DispatchFn InstallDispatcher(ServiceState* state) {
  g_state = state;
  g_pool = std::make_unique<BatchPool>(state->batch_threads);
  state->loads = std::make_unique<LoadQueue>(kMaxQueuedLoads, kLoadWorkers);
  g_finished_loads.reserve(state->loads->MostFinished());
  g_storage.points.resize(FF_MAX_BATCH);
  g_storage.steps.resize(FF_MAX_BATCH);
  g_storage.answers.resize(FF_MAX_BATCH);
  return Dispatch;
}

}  // namespace footfall
