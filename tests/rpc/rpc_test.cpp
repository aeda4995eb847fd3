// footfalld over loopback: RPC answers equal the embedded engine's; misbehaving clients do not
// stop others from being served nor grow the server's memory; clients report a dead server and
// recover after a restart; rpcbind registration answers rpcinfo.
#include <arpa/inet.h>
#include <fcntl.h>
#include <iconv.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall.h"
#include "footfall/client/joined_calls.h"
#include "footfall/client/recent_queries.h"
#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "raw_rpc.h"
#include "server_process.h"

using namespace footfall;
using footfall::test::ServerProcess;
using namespace footfall::test;

namespace {

RawSamples TestTerrain() {
  RawSamples s = MakeHeightField(120, 100, 0.25, 1.5, 42);
  const RawSamples ball = MakeSphere(3000, {15, 3, 12}, 2);
  for (size_t i = 0; i < ball.size(); ++i) s.push_back(ball.points[i], ball.normals[i]);
  return s;
}

// A fresh folder for footfalld's --data-root, removed (with `also`, if set) at the end of the
// test however it ends.
struct TempRoot {
  std::string path, also;
  TempRoot() {
    char tmpl[] = "/tmp/footfall-root-XXXXXX";
    REQUIRE(mkdtemp(tmpl));
    path = tmpl;
  }
  ~TempRoot() {
    std::string command = "rm -rf '" + path + "'";
    if (!also.empty()) command += " '" + also + "'";
    std::system(command.c_str());
  }
  TempRoot(const TempRoot&) = delete;
  TempRoot& operator=(const TempRoot&) = delete;
};

// A floor meeting a wall at a right angle, 2 x 2 and 2 x 1 units.
constexpr const char* kCornerObj =
    "v 0 0 0\nv 2 0 0\nv 2 0 2\nv 0 0 2\nv 2 1 0\nv 2 1 2\nf 1 3 2\nf 1 4 3\nf 2 3 6\nf 2 6 5\n";

// Load options with only a separation (the rest at their defaults).
TerrainLoadOptions Separation(double separation) {
  TerrainLoadOptions o;
  o.separation = separation;
  return o;
}

std::unique_ptr<TerrainSession> Connect(int port, double timeout_s = 5) {
  RpcOptions o;
  o.port = port;
  o.call_timeout_s = timeout_s;
  return MakeRpcSession(o);
}

// A session whose destruction leaves its terrains to footfalld as orphans, as a lost connection
// does.
std::unique_ptr<TerrainSession> ConnectLeavingOrphans(int port) {
  RpcOptions o;
  o.port = port;
  o.call_timeout_s = 5;
  o.unload_on_close = false;
  return MakeRpcSession(o);
}

void RequireSame(const Foothold& a, const Foothold& b) {
  REQUIRE(static_cast<int>(a.status) == static_cast<int>(b.status));
  REQUIRE(a.index == b.index);
  REQUIRE(a.point == b.point);
  REQUIRE(a.normal == b.normal);
}

// Random queries around the test terrain, in and far outside its bounds.
void MakeQueries(size_t n, std::vector<Vec3>* points, std::vector<StepQuery>* steps) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> x(-5, 35), y(-3, 6), z(-5, 30), d(-1, 1);
  for (size_t i = 0; i < n; ++i) {
    Vec3 p{x(rng), y(rng), z(rng)};
    if (i % 50 == 0) p = p * 1000.0;
    points->push_back(p);
    Vec3 dir{d(rng), d(rng) * 0.2, d(rng)};
    if (i % 97 == 0) dir = Vec3{};  // invalid: answered per item
    steps->push_back({p, dir});
  }
}

// --- raw ONC RPC messages, for misbehaving clients ------------------------------------------

int RawConnect(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  return fd;
}

// Sends what fits without blocking; returns bytes sent.
size_t SendSome(int fd, const std::vector<unsigned char>& bytes) {
  const int flags = fcntl(fd, F_GETFL, 0);
  fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  fcntl(fd, F_SETFL, flags);
  return sent;
}

// A well-behaved client still gets correct answers.
void RequireServed(int port) {
  auto rpc = Connect(port, 5);
  TerrainHandle remote = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "probe", &remote) == Status::kOk);
  const Foothold f = rpc->Snap(remote, Vec3{3.2, 1, 4.7});
  REQUIRE(f.status == Status::kOk);
  CHECK(f.point == Vec3{3, 0, 5});
}

// A raw rpcgen client of footfalld on loopback (rpcgen's stubs, no session logic). Its send
// size (libtirpc's default unless given) fragments larger requests, which footfalld drops.
CLIENT* RawClient(int port, u_int send_size = 0) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  int sock = RPC_ANYSOCK;
  CLIENT* c = clnttcp_create(&addr, FOOTFALL_PROG, FOOTFALL_V1, &sock, send_size, send_size);
  REQUIRE(c != nullptr);
  return c;
}

// FF_UPLOAD_BEGIN from a raw client; returns the status, the upload id in *upload.
ff_status BeginUpload(CLIENT* c, uint64_t total, uint32_t* upload, std::string* message) {
  ff_upload_begin_args args;
  args.name = const_cast<char*>("raw");
  args.total = total;
  ff_upload_reply reply{};
  REQUIRE(ff_upload_begin_1(&args, &reply, c) == RPC_SUCCESS);
  *upload = reply.upload;
  *message = reply.message ? reply.message : "";
  const ff_status status = reply.status;
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_upload_reply), reinterpret_cast<char*>(&reply));
  return status;
}

// FF_UPLOAD_CHUNK from a raw client.
ff_status SendChunk(CLIENT* c, uint32_t upload, std::vector<ff_sample> samples,
                    std::string* message) {
  ff_upload_chunk_args args;
  args.upload = upload;
  args.samples.samples_len = static_cast<u_int>(samples.size());
  args.samples.samples_val = samples.data();
  ff_status_reply reply{};
  REQUIRE(ff_upload_chunk_1(&args, &reply, c) == RPC_SUCCESS);
  *message = reply.message ? reply.message : "";
  const ff_status status = reply.status;
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply), reinterpret_cast<char*>(&reply));
  return status;
}

// Sixteen FF_LOADs of "big.pts" (under the server's data root: make it large enough to take a
// while) sent at once on raw connections, replies left unread: footfalld's lane of point files
// and upload grids is full until they are built. Returns the connections (close them).
std::vector<int> FillPointFileLane(int port) {
  std::vector<unsigned char> args;
  Put32(&args, 7);
  for (const char ch : std::string("big.pts\0", 8)) args.push_back(static_cast<unsigned char>(ch));
  PutDouble(&args, 0);
  const std::vector<unsigned char> record = CallRecord(1, FF_LOAD, args);
  std::vector<int> loaders;
  for (int i = 0; i < 16; ++i) {
    loaders.push_back(RawConnect(port));
    REQUIRE(SendSome(loaders.back(), record) == record.size());
  }
  return loaders;
}

// FF_UPLOAD_FINISH from a raw client; returns the status, the terrain in *terrain.
ff_status FinishUpload(CLIENT* c, uint32_t upload, uint32_t* terrain, std::string* message) {
  ff_upload_args args{upload};
  ff_load_reply reply{};
  REQUIRE(ff_upload_finish_1(&args, &reply, c) == RPC_SUCCESS);
  *terrain = reply.terrain;
  *message = reply.message ? reply.message : "";
  const ff_status status = reply.status;
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
  return status;
}

// A complete upload of three samples, not yet finished; returns its id.
uint32_t UploadThreeSamples(CLIENT* c) {
  std::string message;
  uint32_t upload = 0;
  REQUIRE(BeginUpload(c, 3, &upload, &message) == FF_OK);
  REQUIRE(SendChunk(c, upload,
                    {ff_sample{{0, 0, 0}, {0, 1, 0}}, ff_sample{{1, 0, 0}, {0, 1, 0}},
                     ff_sample{{0, 0, 1}, {0, 1, 0}}},
                    &message) == FF_OK);
  return upload;
}

// FF_LOAD_OPTIONS arguments with the loader's defaults (TerrainLoadOptions) for `path`.
ff_load_options_args DefaultLoadOptionsArgs(const char* path) {
  const TerrainLoadOptions o;
  ff_load_options_args args{};
  args.path = const_cast<char*>(path);
  args.separation = o.separation;
  args.smooth_normals = o.smooth_normals;
  args.crease_angle_deg = o.crease_angle_deg;
  args.seed = o.seed;
  args.up_axis = o.up_axis;
  args.height_scale = o.height_scale;
  args.max_samples = o.max_samples;
  return args;
}

// Calls FF_LOAD_OPTIONS with `args` on c, waiting at most `wait` for the reply (a short wait
// sends the load and leaves its reply unread).
clnt_stat CallLoad(CLIENT* c, ff_load_options_args* args, ff_load_reply* reply, timeval wait) {
  return clnt_call(c, FF_LOAD_OPTIONS, reinterpret_cast<xdrproc_t>(xdr_ff_load_options_args),
                   reinterpret_cast<char*>(args), reinterpret_cast<xdrproc_t>(xdr_ff_load_reply),
                   reinterpret_cast<char*>(reply), wait);
}

// The handles of the terrains footfalld holds, in its order (FF_LIST).
std::vector<uint32_t> ServerTerrains(int port) {
  std::vector<uint32_t> handles;
  REQUIRE(ListServerTerrains(port, &handles));
  return handles;
}

// The handle footfalld gave the one terrain it holds, for raw calls (sessions number their
// terrains themselves).
uint32_t OnlyServerTerrain(int port) {
  const std::vector<uint32_t> handles = ServerTerrains(port);
  REQUIRE(handles.size() == 1);
  return handles[0];
}

// FF_INFO from a raw client; returns the status.
ff_status RawInfo(CLIENT* c, uint32_t terrain) {
  ff_terrain_args args{terrain};
  ff_info_reply reply{};
  REQUIRE(ff_info_1(&args, &reply, c) == RPC_SUCCESS);
  const ff_status status = reply.status;
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_info_reply), reinterpret_cast<char*>(&reply));
  return status;
}

// FF_UNLOAD from a raw client; returns the status, the message in *message.
ff_status RawUnload(CLIENT* c, uint32_t terrain, std::string* message) {
  ff_terrain_args args{terrain};
  ff_status_reply reply{};
  REQUIRE(ff_unload_1(&args, &reply, c) == RPC_SUCCESS);
  *message = reply.message ? reply.message : "";
  const ff_status status = reply.status;
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply), reinterpret_cast<char*>(&reply));
  return status;
}

// FF_SNAP from a raw client; returns the status.
ff_status RawSnap(CLIENT* c, uint32_t terrain) {
  ff_point_args args{terrain, {1, 0, 1}};
  ff_result reply{};
  REQUIRE(ff_snap_1(&args, &reply, c) == RPC_SUCCESS);
  return reply.status;
}

// Waits up to 10 s for `done`.
bool WaitFor(const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

}  // namespace

TEST_CASE("Server addresses are read as footfalld's --listen writes them", "[rpc]") {
  const std::pair<std::string, std::pair<std::string, int>> good[] = {
      {"10.0.0.2:7000", {"10.0.0.2", 7000}}, {":7001", {"127.0.0.1", 7001}},
      {"7002", {"127.0.0.1", 7002}},         {"[::1]:7003", {"::1", 7003}},
      {"::1:7004", {"::1", 7004}},           {"::1", {"::1", 7407}},
      {"fe80::2", {"fe80::2", 7407}},        {"2001:db8::1", {"2001:db8::1", 7407}}};
  for (const auto& [text, want] : good) {
    INFO(text);
    RpcOptions o;
    std::string error;
    REQUIRE(ParseHostPort(text, &o, &error) == Status::kOk);
    CHECK(o.host == want.first);
    CHECK(o.port == want.second);
  }
  RpcOptions o;
  std::string error;
  CHECK(ParseHostPort("host:0", &o, &error) == Status::kInvalidArgument);
  CHECK(ParseHostPort("host:x", &o, &error) == Status::kInvalidArgument);
  for (const char* bad : {"host: 7407", "host:+7407", "host:-0", " 7407", "host:7407 ", "host:"})
    CHECK(ParseHostPort(bad, &o, &error) == Status::kInvalidArgument);
  // Brackets unclosed or misplaced, colons in a name ("[::1" was host "[:" at port 1).
  for (const char* bad : {"[::1", "::1]:7407", "[[::1]]:7407", "a:b:7407", "[:]:7407"}) {
    INFO(bad);
    CHECK(ParseHostPort(bad, &o, &error) == Status::kInvalidArgument);
    CHECK(error == "'" + std::string(bad) +
                       "': expected HOST:PORT, an IPv6 address in brackets ([::1]:7407) or alone "
                       "(::1)");
  }
  CHECK(ParseHostPort("[::1]", &o, &error) == Status::kInvalidArgument);  // no port after it
}

TEST_CASE("RPC answers equal the embedded engine", "[rpc]") {
  ServerProcess server;
  auto rpc = Connect(server.port());
  auto embedded = MakeEmbeddedSession();
  const RawSamples terrain = TestTerrain();
  TerrainHandle remote = 0, local = 0;
  REQUIRE(rpc->LoadSamples(terrain, "test", &remote) == Status::kOk);
  REQUIRE(embedded->LoadSamples(terrain, "test", &local) == Status::kOk);

  std::vector<Vec3> points;
  std::vector<StepQuery> steps;
  MakeQueries(10000, &points, &steps);  // more than one protocol batch
  const size_t n = points.size();
  std::vector<Foothold> a(n), b(n);

  SECTION("snap and normal batches") {
    REQUIRE(rpc->Snap(remote, points.data(), n, a.data()) == Status::kOk);
    REQUIRE(embedded->Snap(local, points.data(), n, b.data()) == Status::kOk);
    for (size_t i = 0; i < n; ++i) RequireSame(a[i], b[i]);
    REQUIRE(rpc->Normal(remote, points.data(), n, a.data()) == Status::kOk);
    for (size_t i = 0; i < n; ++i) RequireSame(a[i], b[i]);
  }
  SECTION("next batches, with and without tolerance") {
    for (double tolerance : {0.0, 0.2}) {
      REQUIRE(rpc->Next(remote, steps.data(), n, tolerance, a.data()) == Status::kOk);
      REQUIRE(embedded->Next(local, steps.data(), n, tolerance, b.data()) == Status::kOk);
      size_t found = 0, invalid = 0;
      for (size_t i = 0; i < n; ++i) {
        RequireSame(a[i], b[i]);
        found += a[i].status == Status::kOk;
        invalid += a[i].status == Status::kInvalidArgument;
      }
      CHECK(found > 100);
      CHECK(invalid > 0);
    }
  }
  SECTION("terrain info") {
    TerrainInfo ri, li;
    REQUIRE(rpc->Info(remote, &ri) == Status::kOk);
    REQUIRE(embedded->Info(local, &li) == Status::kOk);
    CHECK(ri.name == "test");
    CHECK(ri.stats.samples == terrain.size());
    CHECK(ri.stats.bounds_min == li.stats.bounds_min);
    CHECK(ri.stats.bounds_max == li.stats.bounds_max);
    CHECK(ri.stats.cells[0] == li.stats.cells[0]);
    CHECK(ri.stats.bytes == li.stats.bytes);
    CHECK(ri.stats.spacing == li.stats.spacing);
    CHECK(li.stats.spacing > 0);
  }
  SECTION("unload and unknown terrains") {
    REQUIRE(rpc->Unload(remote) == Status::kOk);
    CHECK(rpc->Snap(remote, Vec3{}).status == Status::kUnknownTerrain);
  }
  SECTION("the single-query procedures") {
    CLIENT* c = RawClient(server.port());
    // The session's handle is its own; find the server's through FF_LIST.
    ff_list_reply list{};
    REQUIRE(ff_list_1(nullptr, &list, c) == RPC_SUCCESS);
    REQUIRE(list.terrains.terrains_len == 1);
    const unsigned server_handle = list.terrains.terrains_val[0];
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_list_reply), reinterpret_cast<char*>(&list));
    for (size_t i = 0; i < 300; ++i) {
      ff_point_args pa{server_handle, {points[i].x, points[i].y, points[i].z}};
      ff_result r{};
      REQUIRE(ff_snap_1(&pa, &r, c) == RPC_SUCCESS);
      Foothold f;
      f.status = static_cast<Status>(r.status);
      f.index = r.index;
      f.point = {r.point.x, r.point.y, r.point.z};
      f.normal = {r.normal.x, r.normal.y, r.normal.z};
      RequireSame(f, embedded->Snap(local, points[i]));
      ff_next_args na{server_handle,
                      0,
                      {{steps[i].foot.x, steps[i].foot.y, steps[i].foot.z},
                       {steps[i].direction.x, steps[i].direction.y, steps[i].direction.z}}};
      REQUIRE(ff_next_1(&na, &r, c) == RPC_SUCCESS);
      const Foothold e = embedded->Next(local, steps[i]);
      REQUIRE(static_cast<int>(r.status) == static_cast<int>(e.status));
      if (e.status == Status::kOk) CHECK(r.index == e.index);
    }
    // Recently answered queries are published for live viewers.
    ff_recent_args ra{0};
    ff_recent_reply rr{};
    REQUIRE(ff_recent_1(&ra, &rr, c) == RPC_SUCCESS);
    CHECK(rr.status == FF_OK);
    CHECK(rr.queries.queries_len > 0);
    CHECK(rr.latest >= 600);
    const uint64_t latest = rr.latest;
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_recent_reply), reinterpret_cast<char*>(&rr));
    // Every single query, a refused one too: a next with a NaN tolerance was left out.
    ff_next_args na{server_handle, std::nan(""), {{0, 0, 0}, {1, 0, 0}}};
    ff_result r{};
    REQUIRE(ff_next_1(&na, &r, c) == RPC_SUCCESS);
    CHECK(r.status == FF_INVALID_ARGUMENT);
    ra.after = latest;
    rr = ff_recent_reply{};
    REQUIRE(ff_recent_1(&ra, &rr, c) == RPC_SUCCESS);
    REQUIRE(rr.queries.queries_len == 1);
    CHECK(rr.queries.queries_val[0].op == FF_OP_NEXT);
    CHECK(std::isnan(rr.queries.queries_val[0].tolerance));
    CHECK(rr.queries.queries_val[0].result.status == FF_INVALID_ARGUMENT);
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_recent_reply), reinterpret_cast<char*>(&rr));
    clnt_destroy(c);
  }
}

// FF_LOAD's arguments encoded as xdr_string would, but from a std::string that may hold NUL
// bytes (rpcgen's stub sends a C string).
struct RawLoadArgs {
  std::string path;
  double separation = 0;
};

bool_t EncodeRawLoad(XDR* xdrs, RawLoadArgs* a) {
  char* bytes = a->path.data();
  u_int length = static_cast<u_int>(a->path.size());
  return xdr_bytes(xdrs, &bytes, &length, FF_MAX_PATH) && xdr_double(xdrs, &a->separation);
}

TEST_CASE("A batch past --batch-time-limit lets other clients in and is completed exactly",
          "[rpc][robustness]") {
  // Snaps from 1e10 above flat ground: rounding ties most samples, so each compares all 90,000
  // (a full batch of them on 1M samples held footfalld for 20 s, and other clients timed out).
  ServerProcess server(0, {"--no-rpcbind", "--threads", "1", "--batch-time-limit", "0.05"});
  const RawSamples ground = MakeFlat(300, 0.1, 0);
  std::vector<Vec3> far(FF_MAX_BATCH);
  for (size_t i = 0; i < far.size(); ++i) far[i] = {0.007 * i, 1e10, 0.003 * i};
  auto embedded = MakeEmbeddedSession();
  TerrainHandle e = 0;
  REQUIRE(embedded->LoadSamples(ground, "flat", &e) == Status::kOk);
  std::vector<Foothold> expected(far.size());
  REQUIRE(embedded->Snap(e, far.data(), far.size(), expected.data()) == Status::kOk);

  auto slow = Connect(server.port(), 60);
  auto quick = Connect(server.port(), 60);
  TerrainHandle t = 0, q = 0;
  REQUIRE(slow->LoadSamples(ground, "flat", &t) == Status::kOk);
  REQUIRE(quick->LoadSamples(MakeFlat(10, 1, 0), "small", &q) == Status::kOk);
  std::atomic<int> order{0};
  int slow_done = 0, quick_done = 0;
  std::vector<Foothold> got(far.size());
  Status slow_status = Status::kInternalError;
  std::thread a([&] {
    slow_status = slow->Snap(t, far.data(), far.size(), got.data());
    slow_done = ++order;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the batch under way
  for (int i = 0; i < 3; ++i) CHECK(quick->Snap(q, Vec3{1, 0, 1}).status == Status::kOk);
  quick_done = ++order;
  a.join();
  CHECK(quick_done == 1);  // served while the costly batch went on, not after it
  CHECK(slow_done == 2);
  REQUIRE(slow_status == Status::kOk);
  for (size_t i = 0; i < far.size(); ++i) {
    INFO("query " << i);
    RequireSame(got[i], expected[i]);
  }
  CHECK_THAT(server.Log(), Catch::Contains("past its time limit (0.05 s)"));
  CHECK_THAT(server.Log(), Catch::Contains("to be asked again (client 127.0.0.1:"));

  // A client that never said it asks again (FF_ASK_AGAIN, as the library does) gets batches in
  // parts too: a raw client held every other for a whole batch (20 s and more).
  std::vector<uint32_t> handles = ServerTerrains(server.port());
  REQUIRE(handles.size() == 2);
  std::vector<ff_vec3> wire(far.size());
  for (size_t i = 0; i < far.size(); ++i) wire[i] = {far[i].x, far[i].y, far[i].z};
  auto limited = [&](CLIENT* c) {
    ff_point_batch_args args{};
    args.terrain = handles[0];  // the flat ground, loaded first
    args.points.points_len = static_cast<u_int>(wire.size());
    args.points.points_val = wire.data();
    ff_batch_reply reply{};
    REQUIRE(ff_snap_batch_1(&args, &reply, c) == RPC_SUCCESS);
    REQUIRE(reply.status == FF_OK);
    REQUIRE(reply.results.results_len == wire.size());
    size_t later = 0;
    for (u_int i = 0; i < reply.results.results_len; ++i)
      later += reply.results.results_val[i].status == FF_LIMIT_EXCEEDED;
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_batch_reply), reinterpret_cast<char*>(&reply));
    return later;
  };
  CLIENT* raw = RawClient(server.port(), FF_MAX_REQUEST_BYTES + 8192);
  CHECK(limited(raw) > 0);
  ff_status_reply asked{};
  REQUIRE(ff_ask_again_1(nullptr, &asked, raw) == RPC_SUCCESS);
  CHECK(asked.status == FF_OK);
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply), reinterpret_cast<char*>(&asked));
  CHECK(limited(raw) > 0);
  clnt_destroy(raw);
}

// A full batch of points 1e10 above flat ground at the origin: rounding ties most samples, so
// each snap compares every sample (the costliest valid queries).
std::vector<ff_vec3> FarSnaps() {
  std::vector<ff_vec3> far(FF_MAX_BATCH);
  for (size_t i = 0; i < far.size(); ++i) far[i] = {0.007 * i, 1e10, 0.003 * i};
  return far;
}

TEST_CASE("Connections sending costly batches share --batch-time-limit so others wait one limit",
          "[rpc][robustness]") {
  // Eight raw connections send batches of snaps from 1e10 above flat ground (each query compares
  // every sample) over and over; each had a whole limit per batch, taking turns, so a ping
  // waited eight limits. Shared out, a ping waits about one.
  constexpr double kLimitS = 0.25;
  ServerProcess server(0, {"--no-rpcbind", "--threads", "1", "--batch-time-limit", "0.25"});
  auto quick = Connect(server.port(), 60);
  TerrainHandle t = 0;
  REQUIRE(quick->LoadSamples(MakeFlat(300, 0.1, 0), "flat", &t) == Status::kOk);
  std::vector<ff_vec3> far = FarSnaps();
  const uint32_t handle = OnlyServerTerrain(server.port());
  std::atomic<bool> stop{false};
  std::atomic<int> cut_batches{0};
  std::vector<std::thread> costly;
  struct Joined {  // the costly clients end with the test, whatever fails
    std::atomic<bool>& stop;
    std::vector<std::thread>& threads;
    ~Joined() {
      stop = true;
      for (std::thread& c : threads) c.join();
    }
  } joined{stop, costly};
  for (int c = 0; c < 8; ++c) {
    costly.emplace_back([&] {
      CLIENT* raw = RawClient(server.port(), FF_MAX_REQUEST_BYTES + 8192);
      timeval wait{60, 0};
      clnt_control(raw, CLSET_TIMEOUT, reinterpret_cast<char*>(&wait));
      ff_point_batch_args args{};
      args.terrain = handle;
      args.points.points_len = static_cast<u_int>(far.size());
      args.points.points_val = far.data();
      while (!stop) {
        ff_batch_reply reply{};
        if (ff_snap_batch_1(&args, &reply, raw) != RPC_SUCCESS) break;
        if (reply.results.results_len > 0 &&
            reply.results.results_val[reply.results.results_len - 1].status == FF_LIMIT_EXCEEDED)
          ++cut_batches;
        xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_batch_reply), reinterpret_cast<char*>(&reply));
      }
      clnt_destroy(raw);
    });
  }
  CHECK(WaitFor([&] { return cut_batches >= 16; }));  // every connection under way
  double worst_s = 0;
  for (int i = 0; i < 6; ++i) {
    const auto begin = std::chrono::steady_clock::now();
    CHECK(quick->Snap(t, Vec3{1, 0, 1}).status == Status::kOk);
    worst_s = std::max(
        worst_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
  }
  INFO("the longest a snap waited: " << worst_s << " s");
  CHECK(worst_s < 3 * kLimitS);  // eight limits (2 s) before
  CHECK_THAT(server.Log(), Catch::Contains("--batch-time-limit shared with other connections "
                                           "sending costly batches"));
}

TEST_CASE("A connection whose batch was cut waits while the clients ready meanwhile are served",
          "[rpc][robustness]") {
  // A costly connection's next batch, in with a ping sent during its cut batch, was served first
  // whenever its socket's number was the lower: the ping waited two time limits, not one. Here
  // the costly connection is the first, and sends its next batch before the ping.
  ServerProcess server(0, {"--no-rpcbind", "--threads", "1", "--batch-time-limit", "0.25"});
  auto loader = Connect(server.port(), 60);
  TerrainHandle t = 0;
  REQUIRE(loader->LoadSamples(MakeFlat(300, 0.1, 0), "flat", &t) == Status::kOk);
  std::vector<unsigned char> args;
  Put32(&args, OnlyServerTerrain(server.port()));
  const std::vector<ff_vec3> far = FarSnaps();
  Put32(&args, static_cast<uint32_t>(far.size()));
  for (const ff_vec3& p : far) PutDouble(&args, p.x), PutDouble(&args, p.y), PutDouble(&args, p.z);
  const int costly = RawConnect(server.port());  // the lower socket number
  const int pinger = RawConnect(server.port());
  auto send_all = [](int fd, const std::vector<unsigned char>& bytes) {
    for (size_t sent = 0; sent < bytes.size();) {
      const ssize_t n = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      REQUIRE(n > 0);
      sent += static_cast<size_t>(n);
    }
  };
  std::vector<unsigned char> two = CallRecord(1, FF_SNAP_BATCH, args);
  const std::vector<unsigned char> next = CallRecord(2, FF_SNAP_BATCH, args);
  two.insert(two.end(), next.begin(), next.end());
  send_all(costly, two);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the first batch under way
  send_all(pinger, CallRecord(3, FF_NULL, {}));
  // Whole reply records, in the order they arrive.
  std::vector<std::string> order;
  std::vector<unsigned char> buffer;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (order.size() < 3 && std::chrono::steady_clock::now() < deadline) {
    pollfd fds[2] = {{costly, POLLIN, 0}, {pinger, POLLIN, 0}};
    REQUIRE(poll(fds, 2, 1000) >= 0);
    for (const pollfd& p : fds) {
      if (!(p.revents & POLLIN)) continue;
      bool last = false;
      while (!last) {
        unsigned char mark[4];
        REQUIRE(recv(p.fd, mark, 4, MSG_WAITALL) == 4);
        last = (mark[0] & 0x80) != 0;
        const size_t length = (static_cast<size_t>(mark[0] & 0x7f) << 24) |
                              (static_cast<size_t>(mark[1]) << 16) |
                              (static_cast<size_t>(mark[2]) << 8) | mark[3];
        buffer.resize(length);
        REQUIRE(recv(p.fd, buffer.data(), length, MSG_WAITALL) == static_cast<ssize_t>(length));
      }
      order.push_back(p.fd == costly ? "batch" : "ping");
    }
  }
  close(costly);
  close(pinger);
  CHECK(order == std::vector<std::string>{"batch", "ping", "batch"});
}

TEST_CASE("A batch of costly queries keeps to --batch-time-limit within a few milliseconds",
          "[rpc][robustness]") {
  // Snaps from 1e10 above flat ground of 640,000 samples: each compares them all, milliseconds
  // a query (the limit was looked at every 128 queries: a batch of them overran 0.05 s eightfold).
  ServerProcess server(0, {"--no-rpcbind", "--threads", "1", "--batch-time-limit", "0.05"});
  auto session = Connect(server.port(), 60);
  TerrainHandle t = 0;
  REQUIRE(session->LoadSamples(MakeFlat(800, 0.1, 0), "flat", &t) == Status::kOk);
  std::vector<ff_vec3> far = FarSnaps();
  CLIENT* raw = RawClient(server.port(), FF_MAX_REQUEST_BYTES + 8192);
  ff_status_reply asked{};
  REQUIRE(ff_ask_again_1(nullptr, &asked, raw) == RPC_SUCCESS);
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_status_reply), reinterpret_cast<char*>(&asked));
  ff_point_batch_args args{};
  args.terrain = OnlyServerTerrain(server.port());
  args.points.points_len = static_cast<u_int>(far.size());
  args.points.points_val = far.data();
  for (int call = 0; call < 3; ++call) {
    ff_batch_reply reply{};
    const auto begin = std::chrono::steady_clock::now();
    REQUIRE(ff_snap_batch_1(&args, &reply, raw) == RPC_SUCCESS);
    const double took_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    REQUIRE(reply.status == FF_OK);
    REQUIRE(reply.results.results_len == far.size());
    size_t answered = 0, later = 0;
    for (u_int i = 0; i < reply.results.results_len; ++i) {
      answered += reply.results.results_val[i].status == FF_OK;
      later += reply.results.results_val[i].status == FF_LIMIT_EXCEEDED;
    }
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_batch_reply), reinterpret_cast<char*>(&reply));
    INFO("call " << call << ": " << answered << " answered in " << took_s << " s");
    CHECK(answered >= 1);
    CHECK(answered + later == far.size());
    CHECK(later > 0);
    CHECK(took_s < 0.05 + 0.04);
  }
  clnt_destroy(raw);
}

TEST_CASE("footfalld confines server-side loads to its data root", "[rpc]") {
  TempRoot temp;
  const std::string& root = temp.path;
  const std::string outside = root + "-outside";  // a folder beside the root
  temp.also = outside;
  {
    REQUIRE(mkdir(outside.c_str(), 0700) == 0);
    std::ofstream(root + "/ok.pts") << "0 0 0 0 1 0\n1 0 0 0 1 0\n";
    std::ofstream(root + "/bad.pts") << "0 0 0 0 1 0\n1 0 zero 0 1 0\n";
    std::ofstream(outside + "/there.pts") << "0 0 0 0 1 0\n";
    REQUIRE(symlink((outside + "/there.pts").c_str(), (root + "/link.pts").c_str()) == 0);
    REQUIRE(symlink((outside + "/gone.pts").c_str(), (root + "/dangling.pts").c_str()) == 0);
    REQUIRE(symlink(outside.c_str(), (root + "/out").c_str()) == 0);
    // Links that stay within the root: a loop, and a chain of 20 to a missing file.
    REQUIRE(symlink("loop-b.pts", (root + "/loop-a.pts").c_str()) == 0);
    REQUIRE(symlink("loop-a.pts", (root + "/loop-b.pts").c_str()) == 0);
    std::string previous = "missing.pts";
    for (int i = 1; i <= 20; ++i) {
      const std::string name = "chain" + std::to_string(i) + ".pts";
      REQUIRE(symlink(previous.c_str(), (root + "/" + name).c_str()) == 0);
      previous = name;
    }
    // 25 folder links, then 20 file links to a file that is there: 45 links on the way.
    REQUIRE(mkdir((root + "/real").c_str(), 0700) == 0);
    std::ofstream(root + "/real/t.pts") << "0 0 0 0 1 0\n";
    previous = "t.pts";
    for (int i = 1; i <= 20; ++i) {
      const std::string name = "file" + std::to_string(i) + ".pts";
      REQUIRE(symlink(previous.c_str(), (root + "/real/" + name).c_str()) == 0);
      previous = name;
    }
    previous = "real";
    for (int i = 1; i <= 25; ++i) {
      const std::string name = "folder" + std::to_string(i);
      REQUIRE(symlink(previous.c_str(), (root + "/" + name).c_str()) == 0);
      previous = name;
    }
    // 45 links within the root, then one out of it, to a file there and to one that is not.
    for (const std::string target : {"there", "gone"}) {
      previous = outside + "/" + target + ".pts";
      for (int i = 1; i <= 45; ++i) {
        const std::string name = "long-" + target + std::to_string(i) + ".pts";
        REQUIRE(symlink(previous.c_str(), (root + "/" + name).c_str()) == 0);
        previous = name;
      }
    }
  }
  ServerProcess server(0, {"--no-rpcbind", "--data-root", root});
  auto rpc = Connect(server.port());
  TerrainHandle t = 0;
  CHECK(rpc->LoadServerFile("ok.pts", Separation(0), &t) == Status::kOk);
  CHECK(rpc->Snap(t, Vec3{0.9, 0, 0}).index == 1);
  CHECK(rpc->LoadServerFile("/etc/passwd", Separation(0), &t) == Status::kAccessDenied);
  CHECK(rpc->last_error() == "'/etc/passwd': expected a path relative to the data root");
  // An empty path is a malformed request, not a path outside the root.
  CHECK(rpc->LoadServerFile("", Separation(0), &t) == Status::kInvalidArgument);
  CHECK(rpc->last_error() == "expected a path relative to the data root, got an empty path");
  CHECK(rpc->LoadServerFile("missing.pts", Separation(0), &t) == Status::kIoError);
  CHECK(rpc->LoadServerFile("nowhere/missing.pts", Separation(0), &t) == Status::kIoError);
  REQUIRE(rpc->LoadServerFile("bad.pts", Separation(0), &t) == Status::kParseError);
  CHECK(rpc->last_error() ==
        "bad.pts:2: column 3: 'zero' is not a number (expected x y z nx ny nz)");
  CHECK(server.Log().find("error: load") != std::string::npos);

  SECTION("paths leaving the root get one answer, whether their targets exist or not") {
    const std::string base = root.substr(root.rfind('/') + 1) + "-outside/";
    for (const std::string& path : std::vector<std::string>{
             "../" + base + "there.pts", "../" + base + "gone.pts",
             "sub/../../" + base + "there.pts", "link.pts", "dangling.pts", "long-there45.pts",
             "long-gone45.pts", "out/there.pts", "out/gone.pts", "out/no/such/dir.pts"}) {
      INFO(path);
      CHECK(rpc->LoadServerFile(path, Separation(0), &t) == Status::kAccessDenied);
      CHECK(rpc->last_error() == "'" + path + "' leads outside the data root");
    }
  }
  SECTION("links that stay within the root are told as such, not as leaving it") {
    CHECK(rpc->LoadServerFile("loop-a.pts", Separation(0), &t) == Status::kIoError);
    CHECK(rpc->last_error() ==
          "'loop-a.pts': more than 40 symbolic links on its way under the data root (a loop of "
          "links?)");
    CHECK(rpc->LoadServerFile("chain20.pts", Separation(0), &t) == Status::kIoError);
    CHECK(rpc->last_error() == "'chain20.pts': no such file under the data root");
    CHECK(rpc->LoadServerFile("folder25/file20.pts", Separation(0), &t) == Status::kIoError);
    CHECK_THAT(rpc->last_error(), Catch::Contains("more than 40 symbolic links"));
    CHECK(rpc->LoadServerFile("folder20/file20.pts", Separation(0), &t) == Status::kOk);
  }
  SECTION("a path through a file, a name too long, and a long path keep their reasons") {
    // (Each was "no such file under the data root"; a path near FF_MAX_PATH lost its reason
    // at the message's end.)
    CHECK(rpc->LoadServerFile("ok.pts/", Separation(0), &t) == Status::kIoError);
    CHECK(rpc->last_error() ==
          "'ok.pts/': not a directory: a file on its way under the data "
          "root is followed by more of the path");
    CHECK(rpc->LoadServerFile("ok.pts/x.pts", Separation(0), &t) == Status::kIoError);
    CHECK_THAT(rpc->last_error(), Catch::Contains("not a directory"));
    const std::string long_name(300, 'n');
    CHECK(rpc->LoadServerFile(long_name + ".pts", Separation(0), &t) == Status::kIoError);
    CHECK_THAT(rpc->last_error(), Catch::EndsWith("file name too long (a name on its way is over "
                                                  "255 bytes, or the whole path over 4096)"));
    std::string deep;
    while (deep.size() < 1000) deep += "folder/";
    deep += "x.pts";
    CHECK(rpc->LoadServerFile(deep, Separation(0), &t) == Status::kIoError);
    CHECK(rpc->last_error().size() <= FF_MAX_MESSAGE);
    CHECK_THAT(rpc->last_error(), Catch::StartsWith("'folder/folder/") &&
                                      Catch::Contains(" ... ") &&
                                      Catch::EndsWith("folder/x.pts': no such file under the "
                                                      "data root"));
  }
  SECTION("a path with a NUL byte is refused, not cut short") {
    CLIENT* c = RawClient(server.port());
    RawLoadArgs args;
    args.path = std::string("ok.pts\0../x", 11);
    ff_load_reply reply{};
    const timeval timeout{10, 0};
    REQUIRE(clnt_call(c, FF_LOAD, reinterpret_cast<xdrproc_t>(EncodeRawLoad),
                      reinterpret_cast<char*>(&args),
                      reinterpret_cast<xdrproc_t>(xdr_ff_load_reply),
                      reinterpret_cast<char*>(&reply), timeout) == RPC_SUCCESS);
    CHECK(reply.status == FF_INVALID_ARGUMENT);
    CHECK(std::string(reply.message) ==
          "path has a NUL byte at offset 6: expected a path without NUL bytes");
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
    clnt_destroy(c);
  }
}

TEST_CASE("footfalld refuses files that are not regular and keeps serving", "[rpc][robustness]") {
  const TempRoot temp;
  const std::string& root = temp.path;
  REQUIRE(mkfifo((root + "/fifo.pts").c_str(), 0600) == 0);  // open() for reading would block
  REQUIRE(mkdir((root + "/dir.pts").c_str(), 0700) == 0);
  const int unix_socket = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s/socket.pts", root.c_str());
  REQUIRE(bind(unix_socket, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0);
  ServerProcess server(0, {"--no-rpcbind", "--data-root", root});
  // A generous timeout: a server stuck opening the FIFO would answer nobody within it.
  auto rpc = Connect(server.port(), 20);
  const std::pair<const char*, const char*> cases[] = {
      {"fifo.pts", "'fifo.pts' is a FIFO: expected a regular terrain file"},
      {"dir.pts", "'dir.pts' is a directory: expected a regular terrain file"},
      {"socket.pts", "'socket.pts' is a socket: expected a regular terrain file"}};
  for (const auto& c : cases) {
    TerrainHandle t = 0;
    CHECK(rpc->LoadServerFile(c.first, Separation(0), &t) == Status::kInvalidArgument);
    CHECK(rpc->last_error() == c.second);
  }
  RequireServed(server.port());  // another client is answered afterwards
  close(unix_socket);
}

TEST_CASE("footfalld escapes control characters from clients in its log", "[rpc][robustness]") {
  const TempRoot temp;
  const std::string& root = temp.path;
  ServerProcess server(0, {"--no-rpcbind", "--data-root", root});
  auto rpc = Connect(server.port());
  TerrainHandle t = 0;
  const std::string forged = "\nfootfalld: forged line\r\x1b[2J\\n";
  REQUIRE(rpc->LoadSamples(MakeFlat(4, 1, 0), "name" + forged, &t) == Status::kOk);
  CHECK(rpc->LoadServerFile("path" + forged, Separation(0), &t) == Status::kIoError);
  const std::string log = server.Log();
  INFO(log);
  CHECK(log.find("'name\\nfootfalld: forged line\\r\\x1b[2J\\\\n' (uploaded)") !=
        std::string::npos);
  CHECK(log.find("'path\\nfootfalld: forged line\\r\\x1b[2J\\\\n': no such file") !=
        std::string::npos);
  CHECK(log.find('\r') == std::string::npos);
  CHECK(log.find('\x1b') == std::string::npos);
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);) {
    CHECK(line.rfind("footfalld: ", 0) == 0);
    CHECK(line.rfind("footfalld: forged", 0) != 0);
  }
}

// True when `text` is well-formed UTF-8, as glibc's iconv decodes it (no overlong forms, no
// surrogates, nothing past U+10FFFF).
bool ValidUtf8(const std::string& text) {
  const iconv_t cd = iconv_open("UTF-32LE", "UTF-8");
  REQUIRE(cd != reinterpret_cast<iconv_t>(-1));
  std::string input = text;
  std::vector<char> output(4 * input.size() + 4);
  char* in = input.data();
  char* out = output.data();
  size_t in_left = input.size(), out_left = output.size();
  const bool ok = iconv(cd, &in, &in_left, &out, &out_left) != static_cast<size_t>(-1);
  iconv_close(cd);
  return ok && in_left == 0;
}

TEST_CASE("An error message footfalld cuts to FF_MAX_MESSAGE bytes ends on a whole character",
          "[rpc][robustness]") {
  TempRoot temp;
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  auto rpc = Connect(server.port());
  // The message quotes the path after one quote: "'/a" then two-byte characters from byte 3
  // on, so byte FF_MAX_MESSAGE falls inside one of them.
  std::string path = "/a";
  while (path.size() + 2 <= FF_MAX_PATH) path += "\xC3\xA9";  // é
  TerrainHandle t = 0;
  CHECK(rpc->LoadServerFile(path, Separation(0), &t) == Status::kAccessDenied);
  const std::string& message = rpc->last_error();
  INFO(message.size());
  CHECK(message.size() >= FF_MAX_MESSAGE - 1);
  CHECK(ValidUtf8(message));
  // The server keeps serving.
  CHECK(rpc->Ping() == Status::kOk);
}

TEST_CASE("A terrain name cut to FF_MAX_NAME bytes ends on a whole character", "[rpc]") {
  ServerProcess server(0, {"--no-rpcbind"});
  auto rpc = Connect(server.port());
  RawSamples samples;
  samples.points = {{0, 0, 0}, {1, 0, 0}};
  samples.normals = {{0, 1, 0}, {0, 1, 0}};
  std::string name = "a";
  while (name.size() < 2 * FF_MAX_NAME) name += "\xC3\xA9";  // é: byte FF_MAX_NAME is inside one
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(samples, name, &t) == Status::kOk);
  TerrainInfo info;
  REQUIRE(rpc->Info(t, &info) == Status::kOk);
  INFO(info.name.size());
  CHECK(info.name.size() >= FF_MAX_NAME - 1);
  CHECK(info.name.size() <= FF_MAX_NAME);
  CHECK(ValidUtf8(info.name));
  CHECK(name.compare(0, info.name.size(), info.name) == 0);
}

TEST_CASE("footfalld escapes bytes that are not UTF-8 from clients in its log",
          "[rpc][robustness]") {
  const TempRoot temp;
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  auto rpc = Connect(server.port());
  // A stray byte, a valid two- and three-byte character, a surrogate, an overlong '/', a code
  // point past U+10FFFF, a C1 control (CSI), and a character cut short at the end.
  const std::string text =
      "\xff\xfe \xc3\xa9 \xe5\x9c\xb0\xe5\xbd\xa2 \xed\xa0\x80 \xc0\xaf \xf4\x90\x80\x80 "
      "\xc2\x9b end \xe5\x9c";
  const std::string escaped =
      "\\xff\\xfe \xc3\xa9 \xe5\x9c\xb0\xe5\xbd\xa2 \\xed\\xa0\\x80 \\xc0\\xaf "
      "\\xf4\\x90\\x80\\x80 "
      "\\xc2\\x9b end \\xe5\\x9c";
  REQUIRE(!ValidUtf8(text));
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(4, 1, 0), "name " + text, &t) == Status::kOk);
  CHECK(rpc->LoadServerFile("path " + text, Separation(0), &t) == Status::kIoError);
  CHECK(rpc->LoadServerFile("dir/" + text + "\n/x.pts", Separation(0), &t) == Status::kIoError);
  const std::string log = server.Log();
  INFO(log);
  CHECK(ValidUtf8(log));
  CHECK_THAT(log, Catch::Contains("'name " + escaped + "' (uploaded)"));
  CHECK_THAT(log, Catch::Contains("'path " + escaped + "': no such file under the data root"));
  CHECK_THAT(log, Catch::Contains("'dir/" + escaped + "\\n/x.pts': no such file"));
  std::istringstream lines(log);
  int loads = 0;
  for (std::string line; std::getline(lines, line);) {
    CHECK(line.rfind("footfalld: ", 0) == 0);
    loads += line.find(escaped) != std::string::npos;
  }
  CHECK(loads == 3);  // one line per event
}

TEST_CASE("footfalld reads server files with every load option, as the embedded engine does",
          "[rpc]") {
  const TempRoot temp;
  const std::string& root = temp.path;
  // A floor meeting a wall at a right angle (sharp below the crease angle, bent above it), and
  // a 4 x 3 height map with a bump.
  std::ofstream(root + "/corner.obj") << kCornerObj;
  std::ofstream(root + "/bump.asc") << "ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
                                       "0 0 0 0\n0 2 1 0\n0 0 0 0\n";
  ServerProcess server(0, {"--no-rpcbind", "--data-root", root});
  auto rpc = Connect(server.port());
  auto local = MakeEmbeddedSession(1);
  // Probes near the floor's edge at the wall, on the wall, and over the height map.
  const std::vector<Vec3> probes = {{1.9, 0.05, 1}, {1.95, 0.5, 1}, {1, 0.1, 1},
                                    {1, 1.5, 1},    {1, 1, 2},      {2, 0.5, 0.5}};
  // Loads `file` both ways with `o`; returns the remote answers after checking they equal the
  // local ones.
  auto load_both = [&](const std::string& file, const TerrainLoadOptions& o) {
    TerrainHandle r = 0, l = 0;
    INFO(file << ": " << rpc->last_error() << " / " << local->last_error());
    REQUIRE(rpc->LoadServerFile(file, o, &r) == Status::kOk);
    REQUIRE(local->LoadServerFile(root + "/" + file, o, &l) == Status::kOk);
    TerrainInfo ri, li;
    REQUIRE(rpc->Info(r, &ri) == Status::kOk);
    REQUIRE(local->Info(l, &li) == Status::kOk);
    CHECK(ri.stats.samples == li.stats.samples);
    std::vector<Foothold> ra(probes.size()), la(probes.size());
    REQUIRE(rpc->Snap(r, probes.data(), probes.size(), ra.data()) == Status::kOk);
    REQUIRE(local->Snap(l, probes.data(), probes.size(), la.data()) == Status::kOk);
    for (size_t i = 0; i < probes.size(); ++i) RequireSame(ra[i], la[i]);
    return ra;
  };
  auto normals_differ = [](const std::vector<Foothold>& a, const std::vector<Foothold>& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i) n += !(a[i].normal == b[i].normal);
    return n;
  };
  TerrainLoadOptions o;
  o.separation = 0.1;
  const auto sharp = load_both("corner.obj", o);
  o.crease_angle_deg = 180;
  const auto bent = load_both("corner.obj", o);
  CHECK(normals_differ(sharp, bent) > 0);  // the crease angle reached the server
  o.smooth_normals = false;
  const auto flat = load_both("corner.obj", o);
  CHECK(normals_differ(flat, bent) > 0);
  o = TerrainLoadOptions{};
  o.separation = 0.2;
  const auto seed1 = load_both("corner.obj", o);
  o.seed = 7;
  const auto seed7 = load_both("corner.obj", o);
  size_t moved = 0;
  for (size_t i = 0; i < seed1.size(); ++i) moved += !(seed1[i].point == seed7[i].point);
  CHECK(moved > 0);
  // Height maps: cell size, height scale and up axis.
  o = TerrainLoadOptions{};
  const auto plain = load_both("bump.asc", o);
  o.cell_size = 0.5, o.height_scale = 0.25, o.up_axis = 'z';
  const auto scaled = load_both("bump.asc", o);
  moved = 0;
  for (size_t i = 0; i < plain.size(); ++i) moved += !(plain[i].point == scaled[i].point);
  CHECK(moved > 0);
  // The client's own sample limit, below the server's budget.
  o = TerrainLoadOptions{};
  TerrainHandle t = 0;
  o.separation = 0.01, o.max_samples = 1000;
  CHECK(rpc->LoadServerFile("corner.obj", o, &t) == Status::kLimitExceeded);
  CHECK_THAT(rpc->last_error(),
             Catch::EndsWith("(limit 1000); choose a separation of at least 0.098"));
  // Bad options: the loader's message, as for a local file.
  o = TerrainLoadOptions{};
  o.crease_angle_deg = 200;
  CHECK(rpc->LoadServerFile("corner.obj", o, &t) == Status::kInvalidArgument);
  CHECK_THAT(rpc->last_error(), Catch::Contains("crease angle must be from 0 to 180 degrees"));
  o.crease_angle_deg = 60, o.up_axis = 'q';
  CHECK(rpc->LoadServerFile("bump.asc", o, &t) == Status::kInvalidArgument);
  CHECK_THAT(rpc->last_error(), Catch::Contains("up axis must be x, y or z"));
  o.up_axis = 'y', o.finest_default = -1;
  CHECK(rpc->LoadServerFile("bump.asc", o, &t) == Status::kInvalidArgument);
  CHECK_THAT(rpc->last_error(),
             Catch::Contains("finest default separation must be a finite number >= 0"));
  // On the wire, an up axis is an int: one that is 'y' only in its low byte is refused, not cut
  // down to 'y'; a NaN crease angle too. The server goes on serving.
  CLIENT* raw = RawClient(server.port());
  ff_load_options_args args = DefaultLoadOptionsArgs("bump.asc");
  args.max_samples = 1000000;
  args.up_axis = 'y' + 256;
  ff_load_reply reply{};
  REQUIRE(ff_load_options_1(&args, &reply, raw) == RPC_SUCCESS);
  CHECK(reply.status == FF_INVALID_ARGUMENT);
  CHECK_THAT(std::string(reply.message), Catch::Contains("up axis must be x, y or z"));
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
  args.up_axis = 'y', args.crease_angle_deg = std::nan("");
  reply = ff_load_reply{};
  REQUIRE(ff_load_options_1(&args, &reply, raw) == RPC_SUCCESS);
  CHECK(reply.status == FF_INVALID_ARGUMENT);
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
  args.crease_angle_deg = 60;
  reply = ff_load_reply{};
  REQUIRE(ff_load_options_1(&args, &reply, raw) == RPC_SUCCESS);
  CHECK(reply.status == FF_OK);
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
  clnt_destroy(raw);
}

TEST_CASE("A server-side load may take longer than a query's call timeout", "[rpc]") {
  const TempRoot temp;
  const std::string& root = temp.path;
  std::ofstream(root + "/corner.obj") << kCornerObj;
  ServerProcess server(0, {"--no-rpcbind", "--data-root", root});
  // About 540,000 samples: a few seconds of resampling, far beyond a half-second call timeout.
  TerrainLoadOptions o;
  o.separation = 0.004;
  RpcOptions ro;
  ro.port = server.port();
  ro.call_timeout_s = 0.5;
  auto rpc = MakeRpcSession(ro);
  TerrainHandle t = 0;
  const auto begin = std::chrono::steady_clock::now();
  INFO(rpc->last_error());
  REQUIRE(rpc->LoadServerFile("corner.obj", o, &t) == Status::kOk);
  CHECK(std::chrono::steady_clock::now() - begin > std::chrono::milliseconds(500));
  TerrainInfo info;
  REQUIRE(rpc->Info(t, &info) == Status::kOk);  // queries wait the call timeout again
  CHECK(info.stats.samples > 400000);
  // Without the longer wait for loads, the same load times out, and says so.
  ro.load_timeout_s = 0;
  auto hasty = MakeRpcSession(ro);
  CHECK(hasty->LoadServerFile("corner.obj", o, &t) == Status::kUnavailable);
  CHECK_THAT(hasty->last_error(), Catch::Contains("no answer within the call timeout of 0.5 s"));
}

TEST_CASE("A terrain of no samples is refused by both sessions and by footfalld", "[rpc]") {
  ServerProcess server;
  auto rpc = Connect(server.port());
  auto embedded = MakeEmbeddedSession(1);
  TerrainHandle t = 0;
  CHECK(embedded->LoadSamples(RawSamples{}, "none", &t) == Status::kInvalidArgument);
  CHECK_THAT(embedded->last_error(), Catch::Contains("none: no samples"));
  CHECK(rpc->LoadSamples(RawSamples{}, "none", &t) == Status::kInvalidArgument);
  CHECK_THAT(rpc->last_error(), Catch::Contains("none: no samples"));
  CLIENT* c = RawClient(server.port());
  uint32_t upload = 0;
  std::string message;
  CHECK(BeginUpload(c, 0, &upload, &message) == FF_INVALID_ARGUMENT);
  CHECK(message == "an upload of no samples (a terrain needs at least one)");
  clnt_destroy(c);
}

// A load that resamples corner.obj (kCornerObj) at 4 mm: about 540,000 samples, seconds of work.
TerrainLoadOptions SlowLoad() {
  TerrainLoadOptions o;
  o.separation = 0.004;
  return o;
}

TEST_CASE("A server-side load does not hold up the other clients", "[rpc]") {
  const TempRoot temp;
  std::ofstream(temp.path + "/corner.obj") << kCornerObj;
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  auto b = Connect(server.port());
  TerrainHandle small = 0;
  REQUIRE(b->LoadServerFile("corner.obj", Separation(0.1), &small) == Status::kOk);
  auto snap_ok = [&] {
    const Vec3 p{0.5, 0.5, 0.5};
    Foothold f;
    return b->Snap(small, &p, 1, &f) == Status::kOk && f.status == Status::kOk;
  };

  SECTION("others are answered while it runs, and it ends with its terrain") {
    std::atomic<bool> sent{false}, done{false};
    Status loaded = Status::kInternalError;
    TerrainHandle big = 0;
    size_t samples = 0;
    std::thread a([&] {
      auto session = Connect(server.port(), 60);
      sent = true;
      loaded = session->LoadServerFile("corner.obj", SlowLoad(), &big);
      done = true;
      TerrainInfo info;
      if (loaded == Status::kOk && session->Info(big, &info) == Status::kOk)
        samples = info.stats.samples;
    });
    while (!sent) std::this_thread::yield();
    // Well after the load request went out, b is answered again and again before it ends (a
    // server busy with the load would answer b's first query only after it).
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    int answered = 0;
    while (!done) {
      REQUIRE(snap_ok());
      answered += !done;
    }
    a.join();
    CHECK(loaded == Status::kOk);
    CHECK(answered >= 10);
    CHECK(samples > 400000);
  }
  SECTION("a load asking for more samples than one load may have is refused, naming the cap") {
    // A client's max_samples of 2^64-1 was held only to the budget (2^28): a small height map
    // sampled that finely kept a load thread busy for minutes and ran out of memory.
    CLIENT* a = RawClient(server.port());
    ff_load_options_args args = DefaultLoadOptionsArgs("corner.obj");
    args.separation = 1e-4;
    args.max_samples = ~u_quad_t{0};
    ff_load_reply reply{};
    REQUIRE(ff_load_options_1(&args, &reply, a) == RPC_SUCCESS);
    CHECK(reply.status == FF_LIMIT_EXCEEDED);
    CHECK_THAT(std::string(reply.message ? reply.message : ""),
               Catch::Contains("samples per load of a mesh or height map"));
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
    clnt_destroy(a);
    CHECK(snap_ok());
  }
  SECTION("a client that goes away meanwhile: its load is dropped, the others go on") {
    CLIENT* a = RawClient(server.port());
    // Sends FF_LOAD_OPTIONS and closes without waiting for the reply.
    ff_load_options_args args = DefaultLoadOptionsArgs("corner.obj");
    args.separation = 0.004;
    ff_load_reply reply{};
    timeval brief{0, 200000};
    CHECK(CallLoad(a, &args, &reply, brief) == RPC_TIMEDOUT);
    clnt_destroy(a);
    CHECK(snap_ok());
    for (int i = 0; i < 600 && server.Log().find("dropped") == std::string::npos; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    CHECK_THAT(server.Log(),
               Catch::Contains("load of 'corner.obj' dropped: its connection closed before it "
                               "finished"));
    CHECK(snap_ok());
    CHECK(ServerTerrains(server.port()).size() == 1);  // b's only
  }
  SECTION("clients that go away while their loads wait: the loads leave the queue at once") {
    // Sixteen slow loads fill the queue (two run, fourteen wait); the fourteen waiting clients
    // go away: their loads are cancelled, and the queue takes new loads while the two still run.
    ff_load_options_args args = DefaultLoadOptionsArgs("corner.obj");
    args.separation = 0.004;
    auto send_load = [&](CLIENT* c, ff_load_reply* reply, timeval wait) {
      return CallLoad(c, &args, reply, wait);
    };
    std::vector<CLIENT*> running, waiting;
    for (int i = 0; i < 16; ++i) {
      CLIENT* c = RawClient(server.port());
      (i < 2 ? running : waiting).push_back(c);
      ff_load_reply reply{};
      CHECK(send_load(c, &reply, timeval{0, 20000}) == RPC_TIMEDOUT);
    }
    for (CLIENT* c : waiting) clnt_destroy(c);
    // Within a second (the running loads take seconds), a new load is queued, its reply waiting
    // for theirs, rather than refused as busy.
    CLIENT* late = RawClient(server.port());
    clnt_stat sent = RPC_SUCCESS;
    std::string refusal;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (sent == RPC_SUCCESS && std::chrono::steady_clock::now() < until) {
      ff_load_reply reply{};
      sent = send_load(late, &reply, timeval{0, 200000});
      if (sent != RPC_SUCCESS) break;
      refusal = reply.message ? reply.message : "";
      xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    INFO(refusal);
    CHECK(sent == RPC_TIMEDOUT);
    const auto cancelled = [&] {
      size_t n = 0;
      const std::string log = server.Log();
      for (size_t at = 0; (at = log.find("load of 'corner.obj' cancelled: its connection closed "
                                         "while it waited its turn",
                                         at)) != std::string::npos;
           ++at)
        ++n;
      return n;
    };
    CHECK(WaitFor([&] { return cancelled() == waiting.size(); }));
    CHECK(snap_ok());
    clnt_destroy(late);
    for (CLIENT* c : running) clnt_destroy(c);
    CHECK(WIFEXITED(server.Terminate()));
  }
  SECTION("SIGTERM during a load stops the server at once") {
    std::thread a([&] {
      auto session = Connect(server.port(), 60);
      TerrainHandle big = 0;
      CHECK(session->LoadServerFile("corner.obj", SlowLoad(), &big) != Status::kOk);
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const int status = server.Terminate();  // waits at most 5 s
    a.join();
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    CHECK_THAT(server.Log(), Catch::Contains("a server-side load was in progress: abandoned"));
  }
  SECTION("at most 16 loads queue; one more is refused at once") {
    // Sends a slow load on each of 16 connections without waiting for the replies (two run,
    // fourteen wait), then a seventeenth.
    std::vector<CLIENT*> clients;
    ff_load_options_args args = DefaultLoadOptionsArgs("corner.obj");
    args.separation = 0.004;
    auto send_load = [&](CLIENT* c, ff_load_reply* reply, timeval wait) {
      return CallLoad(c, &args, reply, wait);
    };
    for (int i = 0; i < 16; ++i) {
      clients.push_back(RawClient(server.port()));
      ff_load_reply reply{};
      CHECK(send_load(clients.back(), &reply, timeval{0, 20000}) == RPC_TIMEDOUT);
    }
    CLIENT* late = RawClient(server.port());
    ff_load_reply reply{};
    REQUIRE(send_load(late, &reply, timeval{5, 0}) == RPC_SUCCESS);
    CHECK(reply.status == FF_UNAVAILABLE);
    CHECK_THAT(std::string(reply.message),
               Catch::Contains("footfalld is busy: 16 mesh and height map loads are being built, "
                               "the most it queues: try again"));
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
    CHECK(snap_ok());  // and the others are still served
    // An upload has a lane of its own: it is not refused.
    TerrainHandle uploaded = 0;
    CHECK(b->LoadSamples(MakeFlat(10, 1, 0), "beside", &uploaded) == Status::kOk);
    clnt_destroy(late);
    for (CLIENT* c : clients) clnt_destroy(c);
    CHECK(WIFEXITED(server.Terminate()));
  }
}

TEST_CASE("The client library waits while footfalld's load queue is full, then loads", "[rpc]") {
  const TempRoot temp;
  std::ofstream(temp.path + "/corner.obj") << kCornerObj;
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  // Two slow loads run, fourteen quick ones wait behind them: the queue is full (16) until the
  // first slow one ends.
  std::vector<CLIENT*> clients;
  auto send_load = [&](double separation) {
    ff_load_options_args args = DefaultLoadOptionsArgs("corner.obj");
    args.separation = separation;
    ff_load_reply reply{};
    const timeval brief{0, 20000};  // sent, not waited for
    clients.push_back(RawClient(server.port()));
    return CallLoad(clients.back(), &args, &reply, brief);
  };
  for (int i = 0; i < 16; ++i) CHECK(send_load(i < 2 ? 0.004 : 0.1) == RPC_TIMEDOUT);
  RpcOptions o;
  o.port = server.port();
  SECTION("a session's load waits its turn and succeeds") {
    auto late = MakeRpcSession(o);
    TerrainHandle t = 0;
    const Status loaded = late->LoadServerFile("corner.obj", Separation(0.1), &t);
    INFO(late->last_error());
    CHECK(loaded == Status::kOk);
  }
  SECTION("past busy_timeout_s it fails, saying the server stayed busy") {
    o.busy_timeout_s = 0;
    auto hasty = MakeRpcSession(o);
    TerrainHandle t = 0;
    CHECK(hasty->LoadServerFile("corner.obj", Separation(0.1), &t) == Status::kUnavailable);
    CHECK_THAT(hasty->last_error(),
               Catch::Contains("load: footfalld at 127.0.0.1:" + std::to_string(server.port()) +
                               " stayed busy for 0 s (RpcOptions::busy_timeout_s): footfalld is "
                               "busy: 16 mesh and height map loads"));
  }
  for (CLIENT* c : clients) clnt_destroy(c);
}

TEST_CASE("Uploads and point files are not held up by slow server-side loads queued before them",
          "[rpc]") {
  const TempRoot temp;
  std::ofstream(temp.path + "/corner.obj") << kCornerObj;
  std::ofstream(temp.path + "/few.pts") << "0 0 0 0 1 0\n1 0 0 0 1 0\n0 0 1 0 1 0\n";
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  // Four slow loads, each seconds of resampling: two run, two wait (two load threads).
  constexpr int kSlow = 4;
  std::atomic<int> sent{0}, finished{0};
  std::vector<std::thread> loaders;
  for (int i = 0; i < kSlow; ++i) {
    loaders.emplace_back([&] {
      auto session = Connect(server.port(), 600);
      TerrainHandle big = 0;
      ++sent;
      session->LoadServerFile("corner.obj", SlowLoad(), &big);
      ++finished;
    });
  }
  while (sent < kSlow) std::this_thread::yield();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the loads reach footfalld
  // An upload and a point file, with the default call timeout: their grids are built at once,
  // not after the loads (the upload timed out behind them), and most loads are still running
  // when they are done.
  auto uploader = Connect(server.port(), 10);
  TerrainHandle t = 0, few = 0;
  const Status uploaded = uploader->LoadSamples(MakeFlat(30, 1, 0), "small", &t);
  const std::string upload_error = uploader->last_error();
  const Status read = uploader->LoadServerFile("few.pts", TerrainLoadOptions{}, &few);
  INFO(upload_error);
  INFO(uploader->last_error());
  const int done_before = finished;
  CHECK(uploaded == Status::kOk);
  CHECK(read == Status::kOk);
  CHECK(done_before <= 1);
  for (std::thread& l : loaders) l.join();
  CHECK(finished == kSlow);
}

TEST_CASE("SIGTERM during a load leaves no private file name behind", "[rpc]") {
  const TempRoot temp, scratch;
  std::ofstream(temp.path + "/corner.obj") << kCornerObj;
  // footfalld pins each file it loads under a private name in $TMPDIR (PinnedFile): its
  // destructor, which removes the name, never runs when a load is abandoned at SIGTERM.
  const char* before = getenv("TMPDIR");
  const std::string saved = before ? before : "";
  setenv("TMPDIR", scratch.path.c_str(), 1);
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  if (before)
    setenv("TMPDIR", saved.c_str(), 1);
  else
    unsetenv("TMPDIR");
  std::thread a([&] {
    auto session = Connect(server.port(), 60);
    TerrainHandle big = 0;
    session->LoadServerFile("corner.obj", SlowLoad(), &big);
  });
  for (int i = 0;
       i < 100 && std::system(("ls '" + scratch.path + "' | grep -q footfalld-").c_str()); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the load has pinned its file
  CHECK(WIFEXITED(server.Terminate()));
  a.join();
  CHECK_THAT(server.Log(), Catch::Contains("a server-side load was in progress: abandoned"));
  CHECK(std::system(("ls -A '" + scratch.path + "' | grep -q .").c_str()) != 0);  // empty
}

TEST_CASE("footfalld holds --max-samples over parallel uploads and mesh loads", "[rpc]") {
  const TempRoot temp;
  const std::string& root = temp.path;
  std::ofstream(root + "/square.obj")  // 10 x 10: 100 square units
      << "v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nf 1 3 2\nf 1 4 3\n";
  ServerProcess server(0, {"--no-rpcbind", "--data-root", root, "--max-samples", "2000"});
  std::string message;

  SECTION("uploads reserve their announced totals until they end") {
    CLIENT* a = RawClient(server.port());
    CLIENT* b = RawClient(server.port());
    uint32_t upload_a = 0, upload_b = 0;
    REQUIRE(BeginUpload(a, 1500, &upload_a, &message) == FF_OK);
    CHECK(BeginUpload(b, 1000, &upload_b, &message) == FF_LIMIT_EXCEEDED);
    CHECK(message ==
          "an upload of 1000 samples does not fit in the sample budget (--max-samples 2000, "
          "1500 in use by loaded terrains and uploads in progress)");
    // Another connection cannot add to a's upload.
    CHECK(SendChunk(b, upload_a, {ff_sample{{0, 0, 0}, {0, 1, 0}}}, &message) ==
          FF_INVALID_ARGUMENT);
    CHECK(message == "no upload " + std::to_string(upload_a) + " in progress on this connection");
    // A client that goes away releases its reservation.
    clnt_destroy(a);
    REQUIRE(ff_null_1(nullptr, nullptr, b) == RPC_SUCCESS);  // the server has seen a close
    CHECK(BeginUpload(b, 1000, &upload_b, &message) == FF_OK);
    // A failed chunk ends the upload and releases it too.
    CHECK(SendChunk(b, upload_b, {ff_sample{{0, 0, 0}, {0, 0, 0}}}, &message) ==
          FF_INVALID_ARGUMENT);
    CHECK(BeginUpload(b, 2000, &upload_b, &message) == FF_OK);
    // So does a finish that comes short, and it says so, as a refused chunk does (the missing
    // chunk sent after it was answered "no upload N in progress", with no word of why).
    uint32_t terrain = 0;
    REQUIRE(SendChunk(b, upload_b, {ff_sample{{0, 0, 0}, {0, 1, 0}}}, &message) == FF_OK);
    CHECK(FinishUpload(b, upload_b, &terrain, &message) == FF_INVALID_ARGUMENT);
    CHECK(message == "upload ended after 1 of 2000 samples; upload " + std::to_string(upload_b) +
                         " is dropped: begin it again");
    CHECK(BeginUpload(b, 2000, &upload_b, &message) == FF_OK);
    clnt_destroy(b);
  }
  SECTION("meshes are refused on the sampler's estimate, naming a separation that fits") {
    auto rpc = Connect(server.port());
    TerrainHandle t = 0;
    CHECK(rpc->LoadServerFile("square.obj", Separation(0.05), &t) == Status::kLimitExceeded);
    CHECK(rpc->last_error() ==
          "square.obj: separation 0.05 would give about 64000 samples (limit 2000); choose a "
          "separation of at least 0.283 (the limit is what is left of the sample budget "
          "(--max-samples 2000, 0 in use by loaded terrains and uploads in progress))");
    CHECK(rpc->LoadServerFile("square.obj", Separation(0.283), &t) == Status::kOk);
  }
  SECTION("orphans make room in the budget, least recently queried first") {
    auto first = ConnectLeavingOrphans(server.port());
    auto second = ConnectLeavingOrphans(server.port());
    TerrainHandle t = 0;
    REQUIRE(first->LoadSamples(MakeFlat(30, 1, 0), "first", &t) == Status::kOk);    // 900
    REQUIRE(second->LoadSamples(MakeFlat(30, 1, 0), "second", &t) == Status::kOk);  // 900
    const std::vector<uint32_t> held = ServerTerrains(server.port());  // first's, then second's
    REQUIRE(held.size() == 2);
    auto third = Connect(server.port());
    CHECK(third->LoadSamples(MakeFlat(30, 1, 0), "third", &t) == Status::kLimitExceeded);
    first.reset(), second.reset();  // both orphaned
    CHECK(WaitFor([&] {
      return server.Log().find("terrain " + std::to_string(held[1]) + " orphaned") !=
             std::string::npos;
    }));
    CLIENT* other = RawClient(server.port());
    REQUIRE(RawSnap(other, held[0]) == FF_OK);  // the first is queried again
    REQUIRE(third->LoadSamples(MakeFlat(30, 1, 0), "third", &t) == Status::kOk);
    CHECK(RawInfo(other, held[0]) == FF_OK);
    CHECK(RawInfo(other, held[1]) == FF_UNKNOWN_TERRAIN);
    CHECK(server.Log().find("freed orphaned terrain " + std::to_string(held[1]) + " early") !=
          std::string::npos);
    clnt_destroy(other);
  }
  SECTION("a request refused anyway frees no orphan") {
    // (Orphans were freed to make room first, and the request refused after: another client's
    // terrain was gone for nothing.)
    {
      std::ofstream points(root + "/wide.pts");  // 1500 samples
      for (int i = 0; i < 1500; ++i) points << i % 50 << " 0 " << i / 50 << " 0 1 0\n";
    }
    auto first = ConnectLeavingOrphans(server.port());
    TerrainHandle t = 0;
    REQUIRE(first->LoadSamples(MakeFlat(30, 1, 0), "first", &t) == Status::kOk);  // 900
    const std::vector<uint32_t> held = ServerTerrains(server.port());
    REQUIRE(held.size() == 1);
    first.reset();
    CHECK(WaitFor([&] {
      return server.Log().find("terrain " + std::to_string(held[0]) + " orphaned") !=
             std::string::npos;
    }));
    CLIENT* b = RawClient(server.port());
    uint32_t upload = 0, more = 0;
    REQUIRE(BeginUpload(b, 1000, &upload, &message) == FF_OK);  // 1900 of 2000 in use
    // 1000 + 1200 do not fit however many orphans go; nor do 1000 + 1500 loaded from a file.
    CHECK(BeginUpload(b, 1200, &more, &message) == FF_LIMIT_EXCEEDED);
    auto other = Connect(server.port());
    CHECK(other->LoadServerFile("wide.pts", Separation(0.1), &t) == Status::kLimitExceeded);
    CHECK_THAT(other->last_error(), Catch::StartsWith("'wide.pts': 1500 samples do not fit in "
                                                      "the sample budget"));
    CHECK(ServerTerrains(server.port()) == held);  // the orphan stays
    CHECK(server.Log().find("freed orphaned terrain") == std::string::npos);
    // What fits once it goes frees it.
    CHECK(BeginUpload(b, 1000, &more, &message) == FF_OK);
    CHECK(ServerTerrains(server.port()).empty());
    clnt_destroy(b);
  }
}

TEST_CASE("one connection holds at most 4 uploads, and an upload without samples is dropped",
          "[rpc]") {
  // One client could take all 32 upload slots and keep them with an empty chunk now and then:
  // every other client's upload was refused.
  ServerProcess server(0, {"--no-rpcbind", "--upload-timeout", "1"});
  CLIENT* a = RawClient(server.port());
  CLIENT* b = RawClient(server.port());
  std::string message;
  std::vector<uint32_t> held(4);
  for (uint32_t& upload : held) REQUIRE(BeginUpload(a, 10, &upload, &message) == FF_OK);
  uint32_t more = 0;
  CHECK(BeginUpload(a, 10, &more, &message) == FF_LIMIT_EXCEEDED);
  CHECK(message ==
        "this connection has 4 uploads in progress, the most one connection may have: finish "
        "one first");
  uint32_t other = 0;
  REQUIRE(BeginUpload(b, 10, &other, &message) == FF_OK);
  // Empty chunks keep no upload alive; chunks with samples do.
  bool dropped = false;
  std::string why;
  for (int i = 0; i < 10 && !dropped; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    dropped = SendChunk(a, held[0], {}, &why) != FF_OK;
    REQUIRE(SendChunk(b, other, {ff_sample{{0, 0, 1.0 * i}, {0, 1, 0}}}, &message) == FF_OK);
  }
  CHECK(dropped);
  CHECK_THAT(why, Catch::Contains("upload " + std::to_string(held[0]) +
                                  " was dropped: no samples for 1 s (--upload-timeout)"));
  clnt_destroy(a);
  clnt_destroy(b);
  RequireServed(server.port());
}

TEST_CASE("an upload whose finish is refused as busy is kept while its client asks again",
          "[rpc]") {
  // Sixteen loads of a large point file fill the lane that builds point files and upload grids
  // past --upload-timeout (0.1 s; each load takes longer): each finish refused as busy keeps the
  // upload, which the client library finishes again until footfalld has room.
  const TempRoot temp;
  {
    std::ofstream big(temp.path + "/big.pts");
    for (int i = 0; i < 900000; ++i)
      big << i % 600 << " " << (i * 7) % 13 << " " << i / 600 << " 0 1 0\n";
  }
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path, "--upload-timeout", "0.1"});
  CLIENT* c = RawClient(server.port());
  std::string message;
  uint32_t upload = 0;
  REQUIRE(BeginUpload(c, 3, &upload, &message) == FF_OK);
  REQUIRE(SendChunk(c, upload,
                    {ff_sample{{0, 0, 0}, {0, 1, 0}}, ff_sample{{1, 0, 0}, {0, 1, 0}},
                     ff_sample{{0, 0, 1}, {0, 1, 0}}},
                    &message) == FF_OK);
  // Sent at once on raw sockets, replies not read: the lane is full before the first is built.
  const std::vector<int> loaders = FillPointFileLane(server.port());
  // A seventeenth is refused: the lane is full.
  CLIENT* probe = RawClient(server.port());
  ff_load_args load{const_cast<char*>("big.pts"), 0};
  ff_load_reply refused{};
  REQUIRE(ff_load_1(&load, &refused, probe) == RPC_SUCCESS);
  CHECK(refused.status == FF_UNAVAILABLE);
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&refused));
  clnt_destroy(probe);
  // Asks to finish, refused as busy, for longer than --upload-timeout; another client's new
  // upload then drops the uploads idle that long.
  auto finish = [&] {
    ff_upload_args args{upload};
    ff_load_reply loaded{};
    REQUIRE(ff_upload_finish_1(&args, &loaded, c) == RPC_SUCCESS);
    message = loaded.message ? loaded.message : "";
    const ff_status status = loaded.status;
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&loaded));
    return status;
  };
  // Refused for longer than --upload-timeout (polled, as the lane's first load may end soon
  // after: each finish until then must be refused).
  const auto first_refusal = std::chrono::steady_clock::now();
  for (int i = 0; std::chrono::steady_clock::now() - first_refusal < std::chrono::milliseconds(150);
       ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(30));
    INFO("finish " << i);
    REQUIRE(finish() == FF_UNAVAILABLE);
  }
  CLIENT* other = RawClient(server.port());
  uint32_t unused = 0;
  std::string other_message;
  CHECK(BeginUpload(other, 3, &unused, &other_message) == FF_OK);
  clnt_destroy(other);
  ff_status status = FF_UNAVAILABLE;
  const auto begin = std::chrono::steady_clock::now();
  while (status == FF_UNAVAILABLE &&
         std::chrono::steady_clock::now() - begin < std::chrono::seconds(60)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    status = finish();
  }
  INFO(message);
  CHECK(status == FF_OK);
  CHECK_THAT(server.Log(), !Catch::Contains("' dropped: no samples"));
  for (const int l : loaders) close(l);
  clnt_destroy(c);
}

TEST_CASE("a load refused as busy gives its terrain slot back", "[rpc]") {
  // (The slot it held from its request on stayed held: with --max-client-terrains 1 the second
  // try was refused as "holds 0 terrains and loads 1 more", and 256 such refusals over the
  // server's life refused every load.)
  const TempRoot temp;
  {
    std::ofstream big(temp.path + "/big.pts");
    for (int i = 0; i < 300000; ++i)
      big << i % 600 << " " << (i * 7) % 13 << " " << i / 600 << " 0 1 0\n";
    std::ofstream small(temp.path + "/small.pts");
    small << "0 0 0 0 1 0\n1 0 0 0 1 0\n0 0 1 0 1 0\n";
  }
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path, "--max-client-terrains", "1"});
  const std::vector<int> loaders = FillPointFileLane(server.port());
  CLIENT* c = RawClient(server.port());
  auto load_small = [&](std::string* message) {
    ff_load_args load{const_cast<char*>("small.pts"), 0};
    ff_load_reply reply{};
    REQUIRE(ff_load_1(&load, &reply, c) == RPC_SUCCESS);
    *message = reply.message ? reply.message : "";
    const ff_status status = reply.status;
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
    return status;
  };
  std::string message;
  CHECK(load_small(&message) == FF_UNAVAILABLE);  // busy
  // Asked again until footfalld has room: busy, then loaded, never over the quota.
  ff_status status = FF_UNAVAILABLE;
  const auto begin = std::chrono::steady_clock::now();
  while (status == FF_UNAVAILABLE &&
         std::chrono::steady_clock::now() - begin < std::chrono::seconds(60)) {
    status = load_small(&message);
    if (status == FF_UNAVAILABLE) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  INFO(message);
  CHECK(status == FF_OK);
  for (const int l : loaders) close(l);
  clnt_destroy(c);
}

TEST_CASE("footfalld refuses uploaded samples out of range, per chunk", "[rpc]") {
  ServerProcess server;
  CLIENT* c = RawClient(server.port());
  std::string message;
  uint32_t upload = 0;
  auto refused = [&](const ff_sample& bad) {
    REQUIRE(BeginUpload(c, 2, &upload, &message) == FF_OK);
    CHECK(SendChunk(c, upload, {ff_sample{{0, 0, 0}, {0, 1, 0}}, bad}, &message) ==
          FF_INVALID_ARGUMENT);
    // The upload is gone, and the message says so.
    const std::string dropped =
        "; upload " + std::to_string(upload) + " is dropped: begin it again";
    CHECK(message.size() > dropped.size());
    CHECK(message.compare(message.size() - dropped.size(), dropped.size(), dropped) == 0);
    const std::string why = message.substr(0, message.size() - dropped.size());
    CHECK(SendChunk(c, upload, {ff_sample{{0, 0, 0}, {0, 1, 0}}}, &message) == FF_INVALID_ARGUMENT);
    CHECK(message == "no upload " + std::to_string(upload) + " in progress on this connection");
    return why;
  };
  CHECK(refused({{1e308, 0, 0}, {0, 1, 0}}) ==
        "sample 1: point (1e+308, 0, 0) is out of range (expected coordinates within +-5e+14)");
  CHECK(refused({{0, -4e38, 0}, {0, 1, 0}}) ==
        "sample 1: point (0, -4e+38, 0) is out of range (expected coordinates within +-5e+14)");
  CHECK(refused({{0, 0, 5.0001e14}, {0, 1, 0}}) ==
        "sample 1: point (0, 0, 5.0001e+14) is out of range (expected coordinates within +-5e+14)");
  // Just past the range: its every digit (it was shown rounded onto the limit, "5e+14").
  CHECK(refused({{0, -500000000000000.06, 0}, {0, 1, 0}}) ==
        "sample 1: point (0, -500000000000000.06, 0) is out of range (expected coordinates "
        "within +-5e+14)");
  CHECK(refused({{0, 0, 0}, {0, 0, 0}}) ==
        "sample 1: normal (0, 0, 0) has zero length (expected a non-zero nx ny nz)");

  // Huge finite normals are normalised without overflowing; coordinates at the limit answer.
  auto load = [&](const std::vector<ff_sample>& samples) {
    REQUIRE(BeginUpload(c, samples.size(), &upload, &message) == FF_OK);
    REQUIRE(SendChunk(c, upload, samples, &message) == FF_OK);
    ff_upload_args finish{upload};
    ff_load_reply loaded{};
    REQUIRE(ff_upload_finish_1(&finish, &loaded, c) == RPC_SUCCESS);
    INFO(loaded.message);
    REQUIRE(loaded.status == FF_OK);
    const unsigned terrain = loaded.terrain;
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&loaded));
    return terrain;
  };
  auto snap = [&](unsigned terrain, const ff_vec3& p) {
    ff_point_args at{terrain, p};
    ff_result r{};
    REQUIRE(ff_snap_1(&at, &r, c) == RPC_SUCCESS);
    return r;
  };
  const unsigned tilted = load({{{0, 0, 0}, {1e300, 1e300, 0}}, {{5, 0, 0}, {0, 1, 0}}});
  ff_result r = snap(tilted, {0.1, 0, 0});
  REQUIRE(r.status == FF_OK);
  CHECK(r.normal.x == Approx(std::sqrt(0.5)));
  CHECK(r.normal.y == Approx(std::sqrt(0.5)));
  CHECK(r.normal.z == 0);
  const unsigned far = load({{{5e14, 0, 0}, {0, 1, 0}}, {{5e14, 1, 0}, {0, 1, 0}}});
  r = snap(far, {5e14, 0.9, 0});
  REQUIRE(r.status == FF_OK);
  CHECK(r.index == 1);
  CHECK(r.point.x == 5e14);
  CHECK(r.point.y == Approx(1));
  clnt_destroy(c);
}

TEST_CASE("batch items with NaN or infinite inputs answer FF_INVALID_ARGUMENT", "[rpc]") {
  ServerProcess server;
  auto rpc = Connect(server.port());
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "flat", &t) == Status::kOk);
  CLIENT* c = RawClient(server.port());
  ff_list_reply list{};
  REQUIRE(ff_list_1(nullptr, &list, c) == RPC_SUCCESS);
  REQUIRE(list.terrains.terrains_len == 1);
  const unsigned terrain = list.terrains.terrains_val[0];
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_list_reply), reinterpret_cast<char*>(&list));
  const double nan = std::nan(""), inf = HUGE_VAL;
  std::vector<ff_vec3> points = {{1, 0, 1}, {nan, 0, 1}, {1, inf, 1}, {2, 0, -inf}, {2, 0, 2}};
  const ff_status expected[] = {FF_OK, FF_INVALID_ARGUMENT, FF_INVALID_ARGUMENT,
                                FF_INVALID_ARGUMENT, FF_OK};
  for (const u_int proc : {FF_SNAP_BATCH, FF_NORMAL_BATCH}) {
    ff_point_batch_args args;
    args.terrain = terrain;
    args.points.points_len = static_cast<u_int>(points.size());
    args.points.points_val = points.data();
    ff_batch_reply reply{};
    const timeval timeout{10, 0};
    REQUIRE(clnt_call(c, proc, reinterpret_cast<xdrproc_t>(xdr_ff_point_batch_args),
                      reinterpret_cast<char*>(&args),
                      reinterpret_cast<xdrproc_t>(xdr_ff_batch_reply),
                      reinterpret_cast<char*>(&reply), timeout) == RPC_SUCCESS);
    CHECK(reply.status == FF_OK);
    REQUIRE(reply.results.results_len == points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      INFO("proc " << proc << " item " << i);
      CHECK(reply.results.results_val[i].status == expected[i]);
    }
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_batch_reply), reinterpret_cast<char*>(&reply));
  }
  std::vector<ff_next_query> steps = {{{1, 0, 1}, {1, 0, 0}},
                                      {{nan, 0, 1}, {1, 0, 0}},
                                      {{1, 0, 1}, {inf, 0, 0}},
                                      {{1, 0, 1}, {0, 0, nan}},
                                      {{1, 0, 1}, {0, 0, 1}}};
  ff_next_batch_args next;
  next.terrain = terrain;
  next.tolerance = 0;
  next.queries.queries_len = static_cast<u_int>(steps.size());
  next.queries.queries_val = steps.data();
  ff_batch_reply reply{};
  REQUIRE(ff_next_batch_1(&next, &reply, c) == RPC_SUCCESS);
  CHECK(reply.status == FF_OK);
  REQUIRE(reply.results.results_len == steps.size());
  for (size_t i = 0; i < steps.size(); ++i) {
    INFO("next item " << i);
    CHECK(reply.results.results_val[i].status == expected[i]);
  }
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_batch_reply), reinterpret_cast<char*>(&reply));
  clnt_destroy(c);
  // Through the client library (the fast batch filters on both sides), in a large batch.
  std::vector<Vec3> many(3000, Vec3{1, 0, 1});
  for (size_t i = 7; i < many.size(); i += 101) many[i].y = nan;
  std::vector<Foothold> answers(many.size());
  REQUIRE(rpc->Snap(t, many.data(), many.size(), answers.data()) == Status::kOk);
  for (size_t i = 0; i < many.size(); ++i) {
    INFO("item " << i);
    CHECK(answers[i].status == (std::isnan(many[i].y) ? Status::kInvalidArgument : Status::kOk));
  }
}

TEST_CASE("misbehaving clients leave others served and memory flat", "[rpc][robustness]") {
  ServerProcess server;
  auto loader = Connect(server.port());
  TerrainHandle remote = 0;
  REQUIRE(loader->LoadSamples(TestTerrain(), "test", &remote) == Status::kOk);

  // Each misbehaviour is repeated after a warm-up round: the server's memory must stay flat.
  auto flat = [&](const std::function<void()>& misbehave, int rounds) {
    misbehave();
    const long before = server.RssKiB();
    for (int i = 0; i < rounds; ++i) misbehave();
    const long after = server.RssKiB();
    INFO("server RSS before " << before << " KiB, after " << after << " KiB");
    CHECK(after - before < 8192);
  };
  SECTION("half-sent requests") {
    std::vector<int> held;
    flat(
        [&] {
          const int fd = RawConnect(server.port());
          std::vector<unsigned char> partial;
          Put32(&partial, 0x80000000u | 1000);  // announces 1000 bytes, sends 12
          Put32(&partial, 1), Put32(&partial, 0), Put32(&partial, 2);
          SendSome(fd, partial);
          held.push_back(fd);
          if (held.size() > 20) close(held.front()), held.erase(held.begin());
        },
        100);
    RequireServed(server.port());
    for (int fd : held) close(fd);
  }
  SECTION("half-sent requests announcing a record up to and past the size limit") {
    // A record mark alone, announcing 262,145 to 270,336 bytes (past the transport's buffer,
    // within the old record limit), sent and no more: libtirpc grew its buffer and then spun
    // on the connection, serving no one else, until the sender went away.
    std::vector<int> held;
    for (const uint32_t length : {FF_MAX_REQUEST_BYTES - 4u, FF_MAX_REQUEST_BYTES + 0u,
                                  FF_MAX_REQUEST_BYTES + 1u, FF_MAX_REQUEST_BYTES + 4096u,
                                  FF_MAX_REQUEST_BYTES + 8192u, FF_MAX_REQUEST_BYTES + 8193u}) {
      for (const bool last : {true, false}) {
        INFO("announced " << length << " bytes, last fragment " << last);
        const int fd = RawConnect(server.port());
        std::vector<unsigned char> mark;
        Put32(&mark, (last ? 0x80000000u : 0) | length);
        SendSome(fd, mark);
        held.push_back(fd);
        RequireServed(server.port());
      }
    }
    for (int fd : held) close(fd);
  }
  SECTION("clients that never read their replies") {
    // Full snap batches on the real terrain: 64 large replies nobody reads, per client.
    std::vector<unsigned char> batch;
    Put32(&batch, OnlyServerTerrain(server.port()));
    Put32(&batch, FF_MAX_BATCH);
    for (int i = 0; i < FF_MAX_BATCH; ++i)
      PutDouble(&batch, i % 30), PutDouble(&batch, 0), PutDouble(&batch, 0);
    std::vector<unsigned char> stream;
    for (uint32_t xid = 1; xid <= 64; ++xid) {
      const auto rec = CallRecord(xid, FF_SNAP_BATCH, batch);
      stream.insert(stream.end(), rec.begin(), rec.end());
    }
    std::vector<int> held;
    flat(
        [&] {
          const int fd = RawConnect(server.port());
          SendSome(fd, stream);
          held.push_back(fd);
          if (held.size() > 4) close(held.front()), held.erase(held.begin());
        },
        8);
    RequireServed(server.port());
    for (int fd : held) close(fd);
  }
  SECTION("garbage bytes") {
    std::mt19937 rng(3);
    int round = 0;
    flat(
        [&] {
          const int fd = RawConnect(server.port());
          std::vector<unsigned char> junk(4096 + (round++ % 10) * 1000);
          for (auto& c : junk) c = static_cast<unsigned char>(rng());
          if (round % 2) junk[0] = 0x80;  // a plausible record mark with a huge length
          SendSome(fd, junk);
          close(fd);
        },
        100);
    RequireServed(server.port());
  }
  SECTION("batches claiming more items than they carry") {
    std::vector<unsigned char> args;
    Put32(&args, remote);
    Put32(&args, FF_MAX_BATCH);  // claims 4096 points...
    for (int i = 0; i < 10; ++i) PutDouble(&args, i), PutDouble(&args, 0), PutDouble(&args, 0);
    auto hammer = [&](int count) {
      for (int i = 0; i < count; ++i) {
        const int fd = RawConnect(server.port());
        const auto rec = CallRecord(static_cast<uint32_t>(i + 1), FF_SNAP_BATCH, args);
        SendSome(fd, rec);
        unsigned char reply[256];
        const ssize_t got = recv(fd, reply, sizeof reply, 0);  // a GARBAGE_ARGS reply
        CHECK(got > 0);
        close(fd);
      }
    };
    hammer(100);  // warm up allocator pools
    const long before = server.RssKiB();
    hammer(400);  // a leak of the 96 KiB array would add ~38 MiB
    const long after = server.RssKiB();
    INFO("RSS before " << before << " KiB, after " << after << " KiB");
    CHECK(after - before < 4096);
    RequireServed(server.port());
    // The log names the peer and the likely causes, a record split in fragments among them.
    CHECK_THAT(server.Log(), Catch::Contains("snap batch: malformed request from 127.0.0.1:"));
    CHECK_THAT(server.Log(), Catch::Contains("more than one record fragment"));
  }
  // The loader's terrain is still there and answers.
  CHECK(loader->Snap(remote, Vec3{1, 0, 1}).status == Status::kOk);
}

TEST_CASE("clients that never read their replies are held back while others are served",
          "[rpc][robustness]") {
  ServerProcess server;
  auto loader = Connect(server.port());
  TerrainHandle t = 0;
  REQUIRE(loader->LoadSamples(MakeFlat(30, 1, 0), "flat", &t) == Status::kOk);
  const std::vector<unsigned char> call = FullBatchCall(OnlyServerTerrain(server.port()));
  // Their receive buffers as the system makes them, or small: the server's replies then queue
  // in small buffers, each with its overhead, and fewer bytes fit its socket (replies it took
  // room for did not fit, and its thread spun up to 2 s on each before dropping the client).
  const int receive_buffer = GENERATE(0, 1, 4096);
  INFO("the flooders' SO_RCVBUF: " << receive_buffer);
  Flooder first(server.port(), call, receive_buffer), second(server.port(), call, receive_buffer);
  // Both fill their sockets: the server no longer takes their requests.
  REQUIRE(WaitFor([&] { return first.blocked() > 0 && second.blocked() > 0; }));

  const double cpu_before = server.CpuSeconds();
  const auto start = std::chrono::steady_clock::now();
  // A new client: connects, uploads its own terrain and queries it.
  auto rpc = Connect(server.port(), 10);
  TerrainHandle own = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "own", &own) == Status::kOk);
  const int calls = 20;
  int answered = 0;
  // Bounded, so that a server that stalls on them ends the test in time: it takes 0.5 s here.
  const auto give_up = start + std::chrono::seconds(10);
  for (int i = 0; i < calls && std::chrono::steady_clock::now() < give_up; ++i) {
    const Foothold f = rpc->Snap(own, Vec3{3.2, 1, 4.7});
    INFO(rpc->last_error());
    CHECK(f.status == Status::kOk);
    CHECK(f.point == Vec3{3, 0, 5});
    answered += f.status == Status::kOk;
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = server.CpuSeconds() - cpu_before;
  CHECK(answered == calls);
  INFO("server CPU " << cpu << " s over " << wall << " s");
  CHECK(cpu < 0.5 * wall);  // waiting connections do not make it spin
  // Held back, not dropped (the limit is --unread-timeout, 30 s).
  CHECK(first.drops() == 0);
  CHECK(second.drops() == 0);
  CHECK(loader->Snap(t, Vec3{1, 0, 1}).status == Status::kOk);
}

TEST_CASE("thousands of idle connections cost footfalld little while the others are served",
          "[rpc][robustness]") {
  constexpr int kIdle = 3000;
  rlimit files{};
  REQUIRE(getrlimit(RLIMIT_NOFILE, &files) == 0);
  INFO("this test needs " << kIdle + 200 << " descriptors; the hard limit is " << files.rlim_max);
  REQUIRE(files.rlim_max >= static_cast<rlim_t>(kIdle + 200));
  const rlim_t soft = files.rlim_cur;
  files.rlim_cur = files.rlim_max;
  REQUIRE(setrlimit(RLIMIT_NOFILE, &files) == 0);  // footfalld inherits it
  ServerProcess server;
  auto rpc = Connect(server.port(), 10);
  TerrainHandle own = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "own", &own) == Status::kOk);
  const double cpu_before = server.CpuSeconds();
  std::vector<int> idle;
  for (int i = 0; i < kIdle; ++i) idle.push_back(RawConnect(server.port()));
  // Answered once the server has taken every connection before it (the listen queue is FIFO).
  auto late = Connect(server.port(), 30);
  TerrainHandle late_own = 0;
  CHECK(late->LoadSamples(MakeFlat(10, 1, 0), "late", &late_own) == Status::kOk);
  const double cpu = server.CpuSeconds() - cpu_before;
  for (int i = 0; i < 20; ++i) CHECK(rpc->Snap(own, Vec3{3.2, 1, 4.7}).point == Vec3{3, 0, 5});
  // Asking every socket for its unsent bytes at every turn of the loop made taking 3000
  // connections cost about 8 s of CPU (quadratic; 0.7 s without), and clients waited as long.
  INFO("server CPU to take " << kIdle << " connections: " << cpu << " s");
  CHECK(cpu < 4);
  for (const int fd : idle) close(fd);
  files.rlim_cur = soft;
  setrlimit(RLIMIT_NOFILE, &files);
}

TEST_CASE("at the open descriptor limit footfalld says which connections it closes, and serves on",
          "[rpc][robustness]") {
  // 64 descriptors: libtirpc closes the least recently active connections (the idle owner's
  // first) to take new ones.
  ServerProcess server(0, {"--no-rpcbind"}, 64);
  auto owner = ConnectLeavingOrphans(server.port());
  TerrainHandle owned = 0, dropped = 0;
  REQUIRE(owner->LoadSamples(MakeFlat(10, 1, 0), "owned", &owned) == Status::kOk);
  REQUIRE(owner->LoadSamples(MakeFlat(10, 1, 0), "dropped", &dropped) == Status::kOk);
  const std::vector<uint32_t> held = ServerTerrains(server.port());
  REQUIRE(held.size() == 2);
  std::vector<int> idle;
  for (int i = 0; i < 100; ++i) idle.push_back(RawConnect(server.port()));
  auto late = Connect(server.port(), 30);
  TerrainHandle late_own = 0;
  CHECK(late->LoadSamples(MakeFlat(10, 1, 0), "late", &late_own) == Status::kOk);
  CHECK(late->Snap(late_own, Vec3{3.2, 1, 4.7}).point == Vec3{3, 0, 5});
  for (const int fd : idle) close(fd);
  // An unload first: through a new connection (it was lost, "best effort" on the closed one,
  // and the terrain stayed an orphan for --orphan-timeout).
  CHECK(owner->Unload(dropped) == Status::kOk);
  CHECK(WaitFor([&] { return ServerTerrains(server.port()).size() == 2; }));  // owned, late
  CHECK(server.Log().find("unloaded terrain " + std::to_string(held[1])) != std::string::npos);
  // The owner's connection, closed while idle, is replaced before its next call, which
  // succeeds (it failed once with "the connection closed under the call", footfalld serving).
  const Foothold again = owner->Snap(owned, Vec3{3.2, 1, 4.7});
  CHECK(again.status == Status::kOk);
  CHECK(again.point == Vec3{3, 0, 5});
  const std::string log = server.Log();
  CHECK_THAT(log, Catch::Contains("at the open descriptor limit (64): closed the least recently "
                                  "active connection, from 127.0.0.1:"));
  CHECK_THAT(log, Catch::Contains("closed this way so far; raise the limit"));
  CHECK_THAT(log, Catch::Contains("orphaned: footfalld closed the connection that loaded it, the "
                                  "least recently active, at the open descriptor limit"));
  CHECK_THAT(log, !Catch::Contains("orphaned: the connection that loaded it closed"));
}

TEST_CASE("footfalld listens on IPv6 addresses and logs them in brackets", "[rpc]") {
  SECTION("[::1]:0") {
    ServerProcess server(0, {"--no-rpcbind", "--listen", "[::1]:0"});
    // footfalld says it listens just after it writes its port file.
    const std::string listening = "listening on [::1]:" + std::to_string(server.port()) + " ";
    WaitFor([&] { return server.Log().find(listening) != std::string::npos; });
    CHECK_THAT(server.Log(), Catch::Contains(listening));
    RpcOptions o;
    o.host = "::1";
    o.port = server.port();
    auto rpc = MakeRpcSession(o);
    TerrainHandle t = 0;
    REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "v6", &t) == Status::kOk);
    CHECK(rpc->Snap(t, Vec3{3.2, 1, 4.7}).point == Vec3{3, 0, 5});
    // Messages name the server as --listen and --server read it: in brackets.
    const std::string address = "[::1]:" + std::to_string(server.port());
    CHECK(rpc->Describe() == "rpc " + address);
    RecentQueryFeed feed(o);
    CHECK(feed.Address() == address);
    server.Kill();
    CHECK(rpc->Snap(t, Vec3{3.2, 1, 4.7}).status == Status::kUnavailable);
    CHECK_THAT(rpc->last_error(), Catch::Contains("footfalld at " + address + ": "));
    CHECK(rpc->Snap(t, Vec3{3.2, 1, 4.7}).status == Status::kUnavailable);
    CHECK_THAT(rpc->last_error(), Catch::Contains("footfalld at " + address + ": "));
    std::vector<RecentQuery> recent;
    CHECK(feed.Poll(&recent) == Status::kUnavailable);
    CHECK_THAT(feed.last_error(), Catch::Contains(address));
  }
  const TempRoot temp;
  auto run = [&](const std::string& listen) {
    const std::string log = temp.path + "/log";
    const int status = std::system(("timeout 2 " + std::string(ServerProcess::Path()) +
                                    " --no-rpcbind --listen '" + listen + "' 2>'" + log + "'")
                                       .c_str());
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return std::make_pair(WEXITSTATUS(status), text);
  };
  SECTION("a bare IPv6 address takes the default port") {
    // Listens on [::1]:7407 until `timeout` stops it, or finds that port taken.
    const auto [status, log] = run("::1");
    INFO(log);
    CHECK(status != 2);
    CHECK_THAT(log, Catch::Contains("listening on [::1]:7407 ") ||
                        Catch::Contains("cannot listen on [::1]:7407: "));
    CHECK_THAT(log, !Catch::Contains("cannot resolve"));
  }
  SECTION(
      "a bare IPv6 address and port, and an address alone, read as footfall --server reads "
      "them") {
    // ("::1:PORT" was an address that does not resolve, "::1:4811" the address ::1:4811 at
    // port 7407, and "0.0.0.0" a bad port.)
    for (const std::string listen : {"::1:7409", "0.0.0.0", "localhost"}) {
      const auto [status, log] = run(listen);
      INFO(listen << ": " << log);
      CHECK(status != 2);
      CHECK_THAT(log, !Catch::Contains("cannot resolve"));
      if (listen.front() == ':')
        CHECK_THAT(log, Catch::Contains("listening on [::1]:7409 ") ||
                            Catch::Contains("cannot listen on [::1]:7409: "));
      else
        CHECK_THAT(log, Catch::Contains(":7407"));
    }
  }
  SECTION("a wildcard address is said to listen on every interface") {
    // ("0:0" listened on 0.0.0.0 with the log saying "listening on 0:PORT" alone.)
    for (const char* wildcard : {"0:0", "0.0.0.0:0", "[::]:0"}) {
      const auto [status, log] = run(wildcard);
      INFO(wildcard << ": " << log);
      CHECK(status != 2);
      CHECK_THAT(log, Catch::Contains("footfalld: warning: listening on every interface: any host "
                                      "that reaches this machine may load and query terrains"));
    }
    const auto [status, log] = run("127.0.0.1:0");
    INFO(log);
    CHECK_THAT(log, Catch::Contains("listening on 127.0.0.1:"));
    CHECK_THAT(log, !Catch::Contains("every interface"));
  }
  SECTION("malformed addresses and ports are refused") {
    for (const char* bad : {"[::1", "[]:7", "[::1]x", "[::1]:", "[::1]:70000", "127.0.0.1: 0",
                            "127.0.0.1:+0", " 0", "[::1]: 0", "", "::1:x"}) {
      const auto [status, log] = run(bad);
      INFO(bad << ": " << log);
      CHECK(status == 2);
      CHECK_THAT(log, Catch::Contains("expected ADDR:PORT with a port from 0 to 65535 (an IPv6 "
                                      "address in brackets: [::1]:7407)"));
    }
  }
}

TEST_CASE("footfalld logs unknown terrains and uploads dropped for idleness", "[rpc]") {
  ServerProcess server(0, {"--no-rpcbind", "--upload-timeout", "0.2"});
  CLIENT* c = RawClient(server.port());
  CHECK(RawInfo(c, 12345) == FF_UNKNOWN_TERRAIN);
  CHECK(RawSnap(c, 12346) == FF_UNKNOWN_TERRAIN);
  std::string message;
  CHECK(RawUnload(c, 12347, &message) == FF_UNKNOWN_TERRAIN);
  uint32_t upload = 0;
  REQUIRE(BeginUpload(c, 10, &upload, &message) == FF_OK);
  CHECK(WaitFor([&] { return server.Log().find("dropped: no samples") != std::string::npos; }));
  const std::string log = server.Log();
  CHECK_THAT(log, Catch::Contains("error: info: unknown_terrain: no terrain 12345 (never loaded "
                                  "here, unloaded, or freed as an orphan)"));
  CHECK_THAT(log, Catch::Contains("error: snap: unknown_terrain: no terrain 12346"));
  CHECK_THAT(log, Catch::Contains("error: unload: unknown_terrain: no terrain 12347"));
  CHECK_THAT(log, Catch::Contains("upload " + std::to_string(upload) +
                                  " 'raw' (0 of 10 samples received) dropped: no samples for "
                                  "0.2 s (--upload-timeout)"));
  // The client is told why at its next chunk (it was told only "no upload N in progress").
  CHECK(SendChunk(c, upload, {}, &message) == FF_INVALID_ARGUMENT);
  CHECK(message == "upload " + std::to_string(upload) +
                       " was dropped: no samples for 0.2 s (--upload-timeout); begin it again");
  CHECK(SendChunk(c, upload + 1, {}, &message) == FF_INVALID_ARGUMENT);
  CHECK(message == "no upload " + std::to_string(upload + 1) + " in progress on this connection");
  clnt_destroy(c);
}

TEST_CASE("footfalld logs an upload whose client went away and an unknown procedure", "[rpc]") {
  // (Neither had a log line: an upload left by a killed client vanished without a word.)
  ServerProcess server(0, {"--no-rpcbind"});
  CLIENT* c = RawClient(server.port());
  timeval timeout{5, 0};
  // (xdr_void takes no arguments in libtirpc's declaration: cast through void*.)
  const auto void_xdr = reinterpret_cast<xdrproc_t>(reinterpret_cast<void*>(xdr_void));
  const clnt_stat unknown = clnt_call(c, 99, void_xdr, nullptr, void_xdr, nullptr, timeout);
  CHECK(unknown == RPC_PROCUNAVAIL);
  uint32_t upload = 0;
  std::string message;
  REQUIRE(BeginUpload(c, 10, &upload, &message) == FF_OK);
  clnt_destroy(c);
  const std::string dropped = "upload " + std::to_string(upload) +
                              " 'raw' (0 of 10 samples received) dropped: the connection that "
                              "began it closed before it finished";
  CHECK(WaitFor([&] { return server.Log().find(dropped) != std::string::npos; }));
  CHECK_THAT(server.Log(), Catch::Contains("error: unknown procedure 99 of version 1 from "));
}

TEST_CASE("SIGTERM during a raw client's batch says that stopping waits for it", "[rpc]") {
  ServerProcess server(0, {"--no-rpcbind", "--threads", "1"});
  // Snaps from 1e10 above 1M flat samples: each compares every sample (seconds for a batch).
  auto rpc = Connect(server.port(), 120);
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(1000, 0.01, 0), "flat", &t) == Status::kOk);
  const uint32_t handle = OnlyServerTerrain(server.port());
  std::vector<unsigned char> batch;
  Put32(&batch, handle);
  Put32(&batch, FF_MAX_BATCH);
  for (int i = 0; i < FF_MAX_BATCH; ++i)
    PutDouble(&batch, 0.007 * i), PutDouble(&batch, 1e10), PutDouble(&batch, 0.003 * i);
  const std::vector<unsigned char> record = CallRecord(7, FF_SNAP_BATCH, batch);
  const int raw = RawConnect(server.port());  // never asks again: batches in parts all the same
  REQUIRE(SendSome(raw, record) == record.size());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the batch under way
  REQUIRE(kill(server.pid(), SIGTERM) == 0);
  CHECK(WaitFor([&] {
    return server.Log().find("stopping: waiting for 1 batch in progress") != std::string::npos;
  }));
  CHECK_THAT(server.Log(), Catch::Contains("footfalld: stopping: waiting for 1 batch in progress "
                                           "(up to --batch-time-limit)"));
  close(raw);
}

TEST_CASE("footfalld closes a connection whose replies go unread past --unread-timeout",
          "[rpc][robustness]") {
  ServerProcess server(0, {"--no-rpcbind", "--unread-timeout", "1"});
  auto loader = Connect(server.port());
  TerrainHandle t = 0;
  REQUIRE(loader->LoadSamples(MakeFlat(30, 1, 0), "flat", &t) == Status::kOk);
  {
    Flooder flooder(server.port(), FullBatchCall(OnlyServerTerrain(server.port())));
    REQUIRE(WaitFor([&] { return flooder.drops() > 0; }));
  }
  const std::string log = server.Log();
  INFO(log);
  CHECK(log.find("closing the connection from 127.0.0.1:") != std::string::npos);
  CHECK(log.find("its replies went unread for 1 s") != std::string::npos);
  RequireServed(server.port());
  CHECK(loader->Snap(t, Vec3{1, 0, 1}).status == Status::kOk);
}

TEST_CASE("only the connection that loaded a terrain may unload it", "[rpc]") {
  ServerProcess server;
  auto owner = Connect(server.port());
  TerrainHandle t = 0;
  REQUIRE(owner->LoadSamples(MakeFlat(10, 1, 0), "flat", &t) == Status::kOk);
  const uint32_t handle = OnlyServerTerrain(server.port());
  CLIENT* other = RawClient(server.port());
  std::string message;
  CHECK(RawUnload(other, handle, &message) == FF_ACCESS_DENIED);
  CHECK(message == "terrain " + std::to_string(handle) +
                       " was loaded by another connection: only that connection may unload it");
  // Others may still query and describe it.
  CHECK(RawSnap(other, handle) == FF_OK);
  CHECK(RawInfo(other, handle) == FF_OK);
  CHECK(RawUnload(other, handle + 1, &message) == FF_UNKNOWN_TERRAIN);
  CHECK(owner->Unload(t) == Status::kOk);
  CHECK(RawInfo(other, handle) == FF_UNKNOWN_TERRAIN);
  clnt_destroy(other);
}

TEST_CASE("a closed session unloads its terrains, and any client may unload an orphan", "[rpc]") {
  ServerProcess server;
  CLIENT* other = RawClient(server.port());
  {
    auto closing = Connect(server.port());
    TerrainHandle a = 0, b = 0;
    REQUIRE(closing->LoadSamples(MakeFlat(10, 1, 0), "a", &a) == Status::kOk);
    REQUIRE(closing->LoadSamples(MakeFlat(10, 1, 0), "b", &b) == Status::kOk);
    REQUIRE(ServerTerrains(server.port()).size() == 2);
  }  // closed: both unloaded at once (they stayed for --orphan-timeout, 600 s)
  CHECK(ServerTerrains(server.port()).empty());
  {
    auto leaving = ConnectLeavingOrphans(server.port());
    TerrainHandle t = 0;
    REQUIRE(leaving->LoadSamples(MakeFlat(10, 1, 0), "kept", &t) == Status::kOk);
  }
  const uint32_t orphan = OnlyServerTerrain(server.port());
  CHECK(WaitFor([&] {
    return server.Log().find("terrain " + std::to_string(orphan) + " orphaned") !=
           std::string::npos;
  }));
  CHECK(RawSnap(other, orphan) == FF_OK);
  // Its owner, reconnected, has another connection: any client may unload it (it returned OK
  // to the reconnected owner and kept the terrain).
  std::string message;
  CHECK(RawUnload(other, orphan, &message) == FF_OK);
  CHECK(RawInfo(other, orphan) == FF_UNKNOWN_TERRAIN);
  clnt_destroy(other);
}

TEST_CASE("a closed connection's terrains are freed once unqueried for --orphan-timeout", "[rpc]") {
  ServerProcess server(0, {"--no-rpcbind", "--orphan-timeout", "2"});
  auto owner = ConnectLeavingOrphans(server.port());
  TerrainHandle t = 0;
  REQUIRE(owner->LoadSamples(MakeFlat(10, 1, 0), "flat", &t) == Status::kOk);
  const uint32_t handle = OnlyServerTerrain(server.port());
  CLIENT* other = RawClient(server.port());
  owner.reset();  // its connection closes: the terrain is orphaned
  // Queried by another client for twice the timeout, it stays.
  for (int i = 0; i < 20; ++i) {
    REQUIRE(RawSnap(other, handle) == FF_OK);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  // Unqueried, it goes (FF_INFO is not a query: it does not keep it).
  CHECK(WaitFor([&] { return RawInfo(other, handle) == FF_UNKNOWN_TERRAIN; }));
  const std::string log = server.Log();
  INFO(log);
  CHECK(log.find("terrain " + std::to_string(handle) + " orphaned") != std::string::npos);
  CHECK(log.find("freed orphaned terrain " + std::to_string(handle) + " after 2 s") !=
        std::string::npos);
  clnt_destroy(other);
  RequireServed(server.port());
}

TEST_CASE("at the terrain limit, a new terrain frees the least recently queried orphan", "[rpc]") {
  ServerProcess server(0, {"--no-rpcbind"});
  // Four connections hold 64 terrains each: the server's 256.
  std::vector<std::unique_ptr<TerrainSession>> clients;
  std::vector<uint32_t> first;  // the first connection's terrains, in handle order
  for (int i = 0; i < 4; ++i) {
    clients.push_back(ConnectLeavingOrphans(server.port()));
    for (int k = 0; k < 64; ++k) {
      TerrainHandle t = 0;
      REQUIRE(clients.back()->LoadSamples(MakeFlat(2, 1, 0), "t", &t) == Status::kOk);
    }
    if (i == 0) first = ServerTerrains(server.port());
  }
  REQUIRE(first.size() == 64);
  auto late = Connect(server.port());
  TerrainHandle t = 0;
  CHECK(late->LoadSamples(MakeFlat(2, 1, 0), "late", &t) == Status::kLimitExceeded);
  CHECK(late->last_error() == "too many terrains loaded or being loaded (limit 256)");
  // The upload footfalld kept for finishing again is dropped by the session, which has
  // returned: its samples do not wait out --upload-timeout in the budget.
  CHECK(WaitFor([&] {
    return server.Log().find("upload sent more samples than the 4 announced") != std::string::npos;
  }));
  // The first connection closes: its 64 terrains are orphans; one of them is queried again.
  clients[0].reset();
  CHECK(WaitFor([&] {
    return server.Log().find("terrain " + std::to_string(first[63]) + " orphaned") !=
           std::string::npos;
  }));
  CLIENT* other = RawClient(server.port());
  REQUIRE(RawSnap(other, first[0]) == FF_OK);
  // A new terrain now fits: the least recently queried orphan made room, the queried one stays.
  REQUIRE(late->LoadSamples(MakeFlat(2, 1, 0), "late", &t) == Status::kOk);
  CHECK(RawInfo(other, first[0]) == FF_OK);
  CHECK(RawInfo(other, first[1]) == FF_UNKNOWN_TERRAIN);
  CHECK(RawInfo(other, first[2]) == FF_OK);
  CHECK(server.Log().find("freed orphaned terrain " + std::to_string(first[1]) + " early") !=
        std::string::npos);
  clnt_destroy(other);
}

TEST_CASE("footfalld holds each connection to --max-client-terrains", "[rpc]") {
  ServerProcess server(0, {"--no-rpcbind", "--max-client-terrains", "2"});
  auto first = Connect(server.port());
  TerrainHandle a = 0, b = 0, c = 0;
  REQUIRE(first->LoadSamples(MakeFlat(10, 1, 0), "a", &a) == Status::kOk);
  REQUIRE(first->LoadSamples(MakeFlat(10, 1, 0), "b", &b) == Status::kOk);
  CHECK(first->LoadSamples(MakeFlat(10, 1, 0), "c", &c) == Status::kLimitExceeded);
  CHECK(first->last_error() ==
        "this connection holds 2 terrains, the most one connection may hold "
        "(--max-client-terrains 2): unload one first");
  // Another connection has its own quota; an unload makes room.
  auto second = Connect(server.port());
  CHECK(second->LoadSamples(MakeFlat(10, 1, 0), "d", &c) == Status::kOk);
  REQUIRE(first->Unload(a) == Status::kOk);
  CHECK(first->LoadSamples(MakeFlat(10, 1, 0), "c", &c) == Status::kOk);
}

TEST_CASE("an upload finished without a terrain slot left is kept, to be finished again", "[rpc]") {
  // The samples were dropped with the refusal, though it said "unload one first".
  ServerProcess server(0, {"--no-rpcbind", "--max-client-terrains", "2"});
  CLIENT* c = RawClient(server.port());
  std::string message;
  uint32_t first = 0, second = 0, third = 0;
  REQUIRE(FinishUpload(c, UploadThreeSamples(c), &first, &message) == FF_OK);
  const uint32_t upload_b = UploadThreeSamples(c), upload_c = UploadThreeSamples(c);
  REQUIRE(FinishUpload(c, upload_b, &second, &message) == FF_OK);
  CHECK(FinishUpload(c, upload_c, &third, &message) == FF_LIMIT_EXCEEDED);
  CHECK(message ==
        "this connection holds 2 terrains, the most one connection may hold "
        "(--max-client-terrains 2): unload one first; upload " +
            std::to_string(upload_c) + " is kept: unload a terrain and finish it again");
  REQUIRE(RawUnload(c, first, &message) == FF_OK);
  CHECK(FinishUpload(c, upload_c, &third, &message) == FF_OK);
  CHECK(RawInfo(c, third) == FF_OK);
  clnt_destroy(c);
}

TEST_CASE("a load holds its terrain slot while it is built: others fill only the rest", "[rpc]") {
  // A height map resampled on the server (half a million samples: a few seconds) while other
  // connections fill every terrain slot: the limit refused the load once built, its work
  // lost; now it holds its slot from its request on, and the last of the others is refused.
  const TempRoot temp;
  {
    std::ofstream asc(temp.path + "/dem.asc");
    constexpr int kSide = 200;
    asc << "ncols " << kSide << "\nnrows " << kSide << "\nxllcorner 0\nyllcorner 0\ncellsize 1\n";
    for (int r = 0; r < kSide; ++r) {
      for (int col = 0; col < kSide; ++col) asc << (r * 7 + col * 3) % 11 << ' ';
      asc << '\n';
    }
  }
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  ff_status loaded = FF_INTERNAL_ERROR;
  std::string load_message;
  std::thread loader([&] {
    CLIENT* c = RawClient(server.port());
    timeval wait{120, 0};
    clnt_control(c, CLSET_TIMEOUT, reinterpret_cast<char*>(&wait));
    ff_load_args args{const_cast<char*>("dem.asc"), 0};
    ff_load_reply reply{};
    if (ff_load_1(&args, &reply, c) == RPC_SUCCESS) {
      loaded = reply.status;
      load_message = reply.message ? reply.message : "";
    }
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_load_reply), reinterpret_cast<char*>(&reply));
    clnt_destroy(c);
  });
  // Its request reaches footfalld first (the resampling takes seconds after it).
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // 256 terrains at most, 64 per connection: four connections ask for all 256.
  std::vector<std::unique_ptr<TerrainSession>> fillers;
  int filled = 0;
  std::string refusal;
  for (int i = 0; i < 256; ++i) {
    if (i % 64 == 0) fillers.push_back(Connect(server.port(), 30));
    TerrainHandle h = 0;
    if (fillers.back()->LoadSamples(MakeFlat(4, 1, 0), "fill", &h) == Status::kOk)
      ++filled;
    else
      refusal = fillers.back()->last_error();
  }
  loader.join();
  INFO(load_message);
  CHECK(loaded == FF_OK);
  CHECK(filled == 255);
  CHECK(refusal.find("too many terrains loaded or being loaded (limit 256)") != std::string::npos);
}

TEST_CASE("clients report a dead server and recover after a restart", "[rpc][robustness]") {
  const RawSamples terrain = TestTerrain();
  auto server = std::make_unique<ServerProcess>();
  const int port = server->port();
  auto rpc = Connect(port, 2);
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(terrain, "test", &t) == Status::kOk);
  const Foothold before = rpc->Snap(t, Vec3{5, 1, 5});
  REQUIRE(before.status == Status::kOk);

  SECTION("killed and restarted") {
    server->Kill();
    const Foothold dead = rpc->Snap(t, Vec3{5, 1, 5});
    CHECK(dead.status == Status::kUnavailable);
    CHECK(rpc->last_error().find("footfalld at 127.0.0.1:" + std::to_string(port)) !=
          std::string::npos);
    CHECK(rpc->Snap(t, Vec3{5, 1, 5}).status == Status::kUnavailable);  // still down: same answer
    server = std::make_unique<ServerProcess>(port);
    // The session reconnects and loads its terrain on the new server by itself.
    const Foothold again = rpc->Snap(t, Vec3{5, 1, 5});
    REQUIRE(again.status == Status::kOk);
    RequireSame(again, before);
  }
  SECTION("a server that stops answering times out") {
    kill(server->pid(), SIGSTOP);
    const Foothold stuck = rpc->Snap(t, Vec3{5, 1, 5});
    // The recent-queries feed bounds its timeouts as sessions do: a negative or NaN one is 0
    // (it waited libtirpc's default, 25 s).
    for (const double timeout : {-1.0, std::nan("")}) {
      RpcOptions o;
      o.port = port, o.connect_timeout_s = timeout, o.call_timeout_s = timeout;
      RecentQueryFeed feed(o);
      std::vector<RecentQuery> recent;
      const auto start = std::chrono::steady_clock::now();
      CHECK(feed.Poll(&recent) == Status::kUnavailable);
      CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
    }
    kill(server->pid(), SIGCONT);
    CHECK(stuck.status == Status::kUnavailable);
    INFO(rpc->last_error());
    CHECK(rpc->last_error().find("Timed out") != std::string::npos);
    // ... and says what the timeout was and what may help.
    CHECK(rpc->last_error().find("no answer within the call timeout of") != std::string::npos);
    CHECK(rpc->last_error().find("a longer timeout may help") != std::string::npos);
    const Foothold back = rpc->Snap(t, Vec3{5, 1, 5});
    REQUIRE(back.status == Status::kOk);
    RequireSame(back, before);
  }
  SECTION("an unload after a failed call reaches footfalld once it answers again") {
    // (A failed call dropped the connection, and unloads and closes then asked no one: the
    // terrain stayed an orphan for --orphan-timeout.)
    kill(server->pid(), SIGSTOP);
    CHECK(rpc->Snap(t, Vec3{5, 1, 5}).status == Status::kUnavailable);
    kill(server->pid(), SIGCONT);
    CHECK(rpc->Unload(t) == Status::kOk);
    CHECK(WaitFor([&] { return server->Log().find("unloaded terrain") != std::string::npos; }));
  }
  SECTION("a close after a restart whose footfalld does not answer waits the close timeout") {
    // (It reconnected and waited the session's whole call timeout, 20 s here, before the close
    // timeout of 2 s applied.)
    auto patient = Connect(port, 20);
    TerrainHandle p = 0;
    REQUIRE(patient->LoadSamples(terrain, "patient", &p) == Status::kOk);
    server->Kill();
    server = std::make_unique<ServerProcess>(port);
    kill(server->pid(), SIGSTOP);
    const auto start = std::chrono::steady_clock::now();
    patient.reset();
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    kill(server->pid(), SIGCONT);
    CHECK(took < 8);
  }
  SECTION("nothing listening") {
    auto nobody = Connect(1, 1);  // port 1: refused at once
    TerrainHandle h = 0;
    CHECK(nobody->LoadSamples(terrain, "x", &h) == Status::kUnavailable);
    CHECK(nobody->last_error().find("Connection refused") != std::string::npos);
  }
}

TEST_CASE("footfalld exits naming a --port-file it cannot write and never says it listens",
          "[rpc]") {
  const TempRoot temp;
  const std::string log = temp.path + "/log";
  for (const std::string& port_file :
       {temp.path + "/no/such/dir/port", temp.path /* a directory */,
        std::string("/dev/full") /* opens, then fails on the flush */}) {
    INFO(port_file);
    // `timeout`: a footfalld that went on serving would be stopped (124), not waited for.
    const int status = std::system(("timeout 5 " + std::string(ServerProcess::Path()) +
                                    " --no-rpcbind --listen 127.0.0.1:0 --port-file '" + port_file +
                                    "' 2>'" + log + "'")
                                       .c_str());
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    INFO(text);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 1);
    CHECK_THAT(text, Catch::Contains("footfalld: --port-file " + port_file +
                                     ": cannot write the port there: "));
    CHECK_THAT(text, !Catch::Contains("listening"));
  }
}

TEST_CASE("footfalld stops cleanly on SIGTERM, also with clients connected", "[rpc]") {
  ServerProcess server;
  auto rpc = Connect(server.port());
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "flat", &t) == Status::kOk);
  const int idle = RawConnect(server.port());  // a connection that stays open
  const int status = server.Terminate();
  close(idle);
  REQUIRE(status != -1);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(server.Log().find("footfalld: stopped") != std::string::npos);
  CHECK(rpc->Snap(t, Vec3{1, 0, 1}).status == Status::kUnavailable);
}

TEST_CASE("footfalld registers with rpcbind and answers rpcinfo", "[rpc][rpcbind]") {
  // rpcbind is a test dependency (scripts/install-deps.sh test): start it when not running.
  if (std::system("rpcinfo -p 127.0.0.1 >/dev/null 2>&1") != 0) {
    REQUIRE(std::system("rpcbind -w >/dev/null 2>&1 || rpcbind >/dev/null 2>&1") == 0);
    for (int i = 0; i < 100 && std::system("rpcinfo -p 127.0.0.1 >/dev/null 2>&1") != 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ServerProcess server(0, {});
  // Registered before the port file is written, and said just after.
  WaitFor([&] { return server.Log().find("registered with rpcbind") != std::string::npos; });
  CHECK(server.Log().find("registered with rpcbind") != std::string::npos);
  // Whether rpcinfo reaches footfall's program through rpcbind.
  auto rpcinfo_answers = [] {
    const std::string command = "rpcinfo -t 127.0.0.1 " + std::to_string(FOOTFALL_PROG) + " 1 2>&1";
    FILE* p = popen(command.c_str(), "r");
    REQUIRE(p);
    char buffer[512] = {0};
    const size_t n = fread(buffer, 1, sizeof buffer - 1, p);
    const int rc = pclose(p);
    const std::string out(buffer, n);
    INFO(out);
    return rc == 0 && out.find("ready and waiting") != std::string::npos;
  };
  CHECK(rpcinfo_answers());
  {
    // A second server leaves the first one's registration alone (taking it over left the first
    // unregistered once the second stopped).
    ServerProcess second(0, {});
    const std::string note =
        "rpcbind already has the footfalld on port " + std::to_string(server.port());
    WaitFor([&] { return second.Log().find(note) != std::string::npos; });
    CHECK_THAT(second.Log(), Catch::Contains(note));
  }
  CHECK(rpcinfo_answers());
  // SIGHUP (a closed terminal) stops it cleanly, unregistered (it died registered).
  REQUIRE(kill(server.pid(), SIGHUP) == 0);
  for (int i = 0; i < 100 && server.Log().find("footfalld: stopped") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  CHECK_THAT(server.Log(), Catch::Contains("footfalld: stopped"));
  CHECK_FALSE(rpcinfo_answers());
  // A footfalld that cannot write its --port-file withdraws its registration as it exits.
  const TempRoot temp;
  const int status =
      std::system(("timeout 5 " + std::string(ServerProcess::Path()) +
                   " --listen 127.0.0.1:0 --port-file '" + temp.path + "/no/dir/port' 2>/dev/null")
                      .c_str());
  CHECK(WEXITSTATUS(status) == 1);
  CHECK(std::system(("rpcinfo -p 127.0.0.1 | grep -qw " + std::to_string(FOOTFALL_PROG)).c_str()) !=
        0);
}

TEST_CASE("a client repeating a failing request cannot flood footfalld's log",
          "[rpc][robustness]") {
  // Every refused request wrote a line: thousands a second from one client filled the disk.
  // Error lines are written at most 100 at once and 10 a second after, then counted.
  ServerProcess server;
  CLIENT* c = RawClient(server.port());
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 3000; ++i) REQUIRE(RawSnap(c, 12346) == FF_UNKNOWN_TERRAIN);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(RawSnap(c, 12346) == FF_UNKNOWN_TERRAIN);  // still answered
  // Error lines written, and those said not written (in one line a second or so).
  auto count = [&server](size_t* written, size_t* unwritten) {
    const std::string log = server.Log();
    *written = *unwritten = 0;
    for (size_t at = log.find("error: snap: unknown_terrain"); at != std::string::npos;
         at = log.find("error: snap: unknown_terrain", at + 1))
      ++*written;
    const std::string said =
        " lines (errors, batches past their time limit) not written in the last ";
    for (size_t at = log.find(said); at != std::string::npos; at = log.find(said, at + 1)) {
      const size_t line = log.rfind('\n', at) + 1;
      *unwritten += std::stoul(log.substr(line + std::strlen("footfalld: ")));
      CHECK_THAT(log.substr(at, log.find('\n', at) - at),
                 Catch::EndsWith(" s (more than 100 at once or 10 a second); every request was "
                                 "answered"));
    }
  };
  size_t lines = 0, unwritten = 0;
  CHECK(WaitFor([&] {
    count(&lines, &unwritten);
    return lines + unwritten == 3001;
  }));
  INFO(lines << " lines written, " << unwritten << " not, in " << elapsed << " s");
  CHECK(lines >= 100);
  CHECK(lines <= 100 + 10 * (elapsed + 2));
  clnt_destroy(c);
}

TEST_CASE("an unknown terrain is said alike by every session, whatever the count or tolerance",
          "[rpc]") {
  // Over RPC, batches of no queries on an unknown or unloaded terrain answered OK (the embedded
  // session says unknown_terrain), and a NaN tolerance was judged before the terrain.
  ServerProcess server;
  auto rpc = Connect(server.port());
  auto embedded = MakeEmbeddedSession(1);
  JoinedCalls rpc_joined(*rpc), embedded_joined(*embedded);
  auto rpc_member = rpc_joined.Join(), embedded_member = embedded_joined.Join();
  for (TerrainSession* s : {rpc.get(), embedded.get(), rpc_member.get(), embedded_member.get()}) {
    INFO(s->Describe() << (s == rpc_member.get() || s == embedded_member.get() ? ", joined" : ""));
    TerrainHandle loaded = 0, unloaded = 0;
    REQUIRE(s->LoadSamples(MakeFlat(4, 1, 0), "kept", &loaded) == Status::kOk);
    REQUIRE(s->LoadSamples(MakeFlat(4, 1, 0), "gone", &unloaded) == Status::kOk);
    REQUIRE(s->Unload(unloaded) == Status::kOk);
    Foothold out;
    const Vec3 point{1, 0, 1};
    const StepQuery step{point, {0.5, 0, 0}};
    for (const TerrainHandle t : {unloaded, TerrainHandle{987654}}) {
      CHECK(s->Snap(t, &point, 0, &out) == Status::kUnknownTerrain);
      CHECK(s->Normal(t, &point, 0, &out) == Status::kUnknownTerrain);
      CHECK(s->Next(t, &step, 0, 0, &out) == Status::kUnknownTerrain);
      CHECK(s->Next(t, &step, 1, std::nan(""), &out) == Status::kUnknownTerrain);
    }
    CHECK(s->Snap(loaded, &point, 0, &out) == Status::kOk);
    CHECK(s->Next(loaded, &step, 0, 0, &out) == Status::kOk);
    CHECK(s->Next(loaded, &step, 1, std::nan(""), &out) == Status::kInvalidArgument);
  }
}

namespace {

// How many times the strings `whats` occur in `log`, together.
size_t Occurrences(const std::string& log, std::initializer_list<const char*> whats) {
  size_t count = 0;
  for (const char* what : whats)
    for (size_t at = log.find(what); at != std::string::npos; at = log.find(what, at + 1)) ++count;
  return count;
}

}  // namespace

TEST_CASE("a client loading and unloading in a loop cannot flood footfalld's log",
          "[rpc][robustness]") {
  // Each load and unload wrote a line: a tiny terrain loaded and unloaded in a loop wrote
  // thousands a second. They have a budget as the error lines': 100 at once, 10 a second.
  ServerProcess server;
  auto rpc = Connect(server.port());
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 400; ++i) {
    TerrainHandle t = 0;
    REQUIRE(rpc->LoadSamples(MakeFlat(2, 1, 0), "tiny", &t) == Status::kOk);
    REQUIRE(rpc->Unload(t) == Status::kOk);
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The error lines have a budget of their own: a refusal at once after the loads is said.
  CLIENT* raw = RawClient(server.port());
  CHECK(RawSnap(raw, 12346) == FF_UNKNOWN_TERRAIN);
  clnt_destroy(raw);
  TerrainHandle kept = 0;  // still served
  REQUIRE(rpc->LoadSamples(MakeFlat(10, 1, 0), "kept", &kept) == Status::kOk);
  CHECK(rpc->Snap(kept, Vec3{3.2, 1, 4.7}).point == Vec3{3, 0, 5});
  CHECK(WaitFor([&] {
    return server.Log().find(" lines (loads and unloads) not written in the last ") !=
           std::string::npos;
  }));
  CHECK(WaitFor([&] { return server.Log().find("error: snap") != std::string::npos; }));
  const size_t lines =
      Occurrences(server.Log(), {"footfalld: loaded terrain ", "footfalld: unloaded terrain "});
  INFO(lines << " load and unload lines in " << elapsed << " s");
  CHECK(lines >= 100);
  CHECK(lines <= 100 + 10 * (elapsed + 2));
}

TEST_CASE("clients that load and close in a loop cannot flood footfalld's log",
          "[rpc][robustness]") {
  // Each closed connection's terrain wrote an "orphaned" line, and each freed orphan another,
  // without a budget: a client loading and closing in a loop wrote megabytes a second. They
  // have a budget of their own, as the load lines' (100 at once, 10 a second).
  ServerProcess server(0, {"--no-rpcbind", "--orphan-timeout", "1"});
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 300; ++i) {
    auto rpc = ConnectLeavingOrphans(server.port());
    TerrainHandle t = 0;
    REQUIRE(rpc->LoadSamples(MakeFlat(2, 1, 0), "tiny", &t) == Status::kOk);
  }  // each connection closed with its terrain loaded: an orphan, freed a second later
  CHECK(WaitFor([&] {
    return server.Log().find(
               " lines (orphaned, freed and dropped terrains and uploads) not "
               "written in the last ") != std::string::npos;
  }));
  RequireServed(server.port());
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the orphans freed
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const size_t lines =
      Occurrences(server.Log(), {" orphaned: ", "footfalld: freed orphaned terrain "});
  INFO(lines << " orphaned and freed lines in " << elapsed << " s");
  CHECK(lines >= 100);
  CHECK(lines <= 100 + 10 * (elapsed + 2));
}

TEST_CASE("a client sending costly batches cannot flood footfalld's log", "[rpc][robustness]") {
  // Every batch cut at --batch-time-limit wrote a line: far snaps, sent again and again, wrote
  // about 100 lines a second. They share the error lines' budget: 100 at once, 10 a second.
  ServerProcess server(0, {"--no-rpcbind", "--threads", "1", "--batch-time-limit", "0.001"});
  auto rpc = Connect(server.port(), 60);
  TerrainHandle t = 0;
  REQUIRE(rpc->LoadSamples(MakeFlat(300, 0.1, 0), "flat", &t) == Status::kOk);
  std::vector<Vec3> far(600);
  for (size_t i = 0; i < far.size(); ++i) far[i] = {0.007 * i, 1e10, 0.003 * i};
  std::vector<Foothold> got(far.size());
  const auto t0 = std::chrono::steady_clock::now();
  REQUIRE(rpc->Snap(t, far.data(), far.size(), got.data()) == Status::kOk);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const Foothold& f : got) REQUIRE(f.status == Status::kOk);  // every query answered
  auto count = [&server](const std::string& what) {
    const std::string log = server.Log();
    size_t n = 0;
    for (size_t at = log.find(what); at != std::string::npos; at = log.find(what, at + 1)) ++n;
    return n;
  };
  // The batch was cut hundreds of times (each far snap compares all 90,000 samples), and the lines
  // beyond the budget were counted in a line of their own.
  CHECK(WaitFor([&] { return count(" not written in the last ") > 0; }));
  const size_t lines = count("past its time limit (0.001 s)");
  INFO(lines << " lines written in " << elapsed << " s");
  CHECK(lines >= 100);
  CHECK(lines <= 100 + 10 * (elapsed + 2));
}

// True when the server has closed `fd` (an end of file or a reset), waiting up to `wait_ms`.
static bool ClosedByServer(int fd, int wait_ms) {
  pollfd p{fd, POLLIN, 0};
  if (poll(&p, 1, wait_ms) <= 0) return false;
  char byte;
  const ssize_t n = recv(fd, &byte, 1, MSG_DONTWAIT);
  return n == 0 || (n < 0 && errno == ECONNRESET);
}

// Sends a whole call and reads its whole reply on `fd`; true when one came.
static bool CallRaw(int fd, const std::vector<unsigned char>& record) {
  if (SendSome(fd, record) != record.size()) return false;
  pollfd p{fd, POLLIN, 0};
  if (poll(&p, 1, 5000) <= 0) return false;
  unsigned char reply[512];
  return recv(fd, reply, sizeof reply, 0) > 0;
}

TEST_CASE("footfalld closes connections that send part of a request past --request-timeout",
          "[rpc][robustness]") {
  ServerProcess server(0, {"--no-rpcbind", "--request-timeout", "1"});
  // Part of a request: its record mark announces 1000 bytes, 12 follow.
  std::vector<unsigned char> partial;
  Put32(&partial, 0x80000000u | 1000);
  Put32(&partial, 1), Put32(&partial, 0), Put32(&partial, 2);
  const int stalled = RawConnect(server.port());
  REQUIRE(SendSome(stalled, partial) == partial.size());
  // Idle between requests: after a whole request, and after one that libtirpc refuses itself
  // (version 2), answered without reaching footfalld's procedures.
  const int idle = RawConnect(server.port());
  REQUIRE(CallRaw(idle, CallRecord(1, FF_NULL, {})));
  std::vector<unsigned char> version2 = CallRecord(2, FF_NULL, {});
  version2[4 + 16 + 3] = 2;  // the version word of the call header
  const int refused = RawConnect(server.port());
  REQUIRE(CallRaw(refused, version2));
  const int fresh = RawConnect(server.port());  // has sent nothing yet

  CHECK(ClosedByServer(stalled, 4000));
  CHECK_THAT(server.Log(), Catch::Contains("it sent part of a request and not the rest for"));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  for (const int fd : {idle, refused, fresh}) {
    CHECK_FALSE(ClosedByServer(fd, 0));
    CHECK(CallRaw(fd, CallRecord(3, FF_NULL, {})));
  }
  // The log names the stalled connection only.
  const std::string log = server.Log();
  INFO(log);
  size_t closings = 0;
  for (size_t at = log.find("closing the connection"); at != std::string::npos;
       at = log.find("closing the connection", at + 1))
    ++closings;
  CHECK(closings == 1);
  for (const int fd : {stalled, idle, refused, fresh}) close(fd);
}

TEST_CASE("many connections sending part of a request keep footfalld's memory bounded",
          "[rpc][robustness]") {
  ServerProcess server;
  // 400 connections each send 250,000 bytes of a 260,000-byte request and stop: libtirpc holds
  // the part (about 66 MB in all); past 64 at once, the longest waiting is closed.
  std::vector<unsigned char> part;
  Put32(&part, 0x80000000u | 260000);
  part.resize(250000, 1);
  const long before = server.RssKiB();
  std::vector<int> fds;
  for (int i = 0; i < 400; ++i) {
    fds.push_back(RawConnect(server.port()));
    SendSome(fds.back(), part);
  }
  RequireServed(server.port());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last parts read
  const long flooded = server.RssKiB();
  INFO("RSS before " << before << " KiB, with 400 half-sent requests " << flooded << " KiB");
  CHECK(flooded - before < 32 * 1024);
  CHECK_THAT(server.Log(), Catch::Contains("more connections than 64 sent part of a request"));
  // 336 were closed: a few logged one by one, the others counted in a line.
  CHECK(WaitFor([&] {
    return server.Log().find("more connections that sent part of a request") != std::string::npos;
  }));
  {
    const std::string log = server.Log();
    size_t lines = 0;
    for (size_t at = log.find("closing the connection"); at != std::string::npos;
         at = log.find("closing the connection", at + 1))
      ++lines;
    INFO(log);
    CHECK(lines < 100);
  }
  for (const int fd : fds) close(fd);
  fds.clear();
  // Connections opened after the burst cost what they did before it (their buffers were taken
  // from a heap the burst had written, and held resident, about 270 KB each).
  WaitFor([&] { return server.RssKiB() - before < 8 * 1024; });
  const long drained = server.RssKiB();
  for (int i = 0; i < 200; ++i) {
    fds.push_back(RawConnect(server.port()));
    REQUIRE(CallRaw(fds.back(), CallRecord(1, FF_NULL, {})));
  }
  const long idle = server.RssKiB();
  INFO("RSS after the burst " << drained << " KiB, with 200 idle connections " << idle << " KiB");
  CHECK(idle - drained < 16 * 1024);
  for (const int fd : fds) close(fd);
}

TEST_CASE("a C client on rpcgen's stubs alone calls every procedure of footfalld",
          "[rpc][protocol]") {
  // Over TCP with AUTH_NONE and AUTH_SYS; version 2 and an unknown procedure refused by
  // number; UDP refused at once (tests/rpc/plain_c_client.c prints each check).
  ServerProcess server;
  const std::string command =
      std::string(PLAIN_C_CLIENT) + " " + std::to_string(server.port()) + " 2>&1";
  FILE* p = popen(command.c_str(), "r");
  REQUIRE(p);
  std::string out;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, p)) > 0;) out.append(buffer, n);
  const int status = pclose(p);
  INFO(out);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(out.find("FAILED") == std::string::npos);
  CHECK_THAT(out, Catch::Contains("ok: AUTH_SYS: FF_NEXT_BATCH of FF_MAX_BATCH queries"));
}

TEST_CASE("footfalld logs the separation a mesh was resampled at and when its limit coarsened it",
          "[rpc]") {
  const TempRoot temp;
  std::ofstream(temp.path + "/plane.obj")
      << "v 0 0 0\nv 100 0 0\nv 100 0 100\nv 0 0 100\nf 1 3 2\nf 1 4 3\n";
  ServerProcess server(0, {"--no-rpcbind", "--data-root", temp.path});
  auto rpc = Connect(server.port());
  TerrainHandle t = 0;
  // As fine as 0.05 (a character's quarter step) within 1000 samples: about 5 apart instead.
  TerrainLoadOptions o;
  o.finest_default = 0.05;
  o.max_samples = 1000;
  REQUIRE(rpc->LoadServerFile("plane.obj", o, &t) == Status::kOk);
  REQUIRE(rpc->Unload(t) == Status::kOk);
  // At a separation given: no note.
  o = TerrainLoadOptions{};
  o.separation = 10;
  REQUIRE(rpc->LoadServerFile("plane.obj", o, &t) == Status::kOk);
  const std::string log = server.Log();
  INFO(log);
  CHECK_THAT(log, Catch::Contains("samples at separation 10, grid"));
  CHECK_THAT(log, Catch::Contains(
                      "(coarser than the 0.05 asked: within the limit of 1000 samples, no finer)"));
  size_t notes = 0;
  for (size_t at = log.find("coarser than"); at != std::string::npos;
       at = log.find("coarser than", at + 1))
    ++notes;
  CHECK(notes == 1);
}
