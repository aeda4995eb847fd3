// Structured protocol fuzzing of footfalld. A real footfalld on loopback is sent, over raw TCP,
// calls built here byte by byte (RFC 5531 call header, AUTH_NONE, record marking) for every
// procedure of footfall.x, for unknown procedures, versions and programs: arguments encoded by
// the rpcgen xdr_* routines and then damaged (bits flipped, bytes and words overwritten with 0,
// 0xff, 0x7f, 0x80, cut short, extended with junk, array counts and string lengths replaced with
// huge or negative values, doubles with NaN, infinities, 1e308 or -0), and wholly random bodies;
// some calls split into several record fragments, some sent back to back, some left unread.
//
// Every case is checked against an oracle: the arguments as rpcgen's own routine decodes them.
// A well-framed call must get, within a bounded time, the reply RFC 5531 and libtirpc give it
// (SUCCESS exactly when the arguments decode, else GARBAGE_ARGS; PROC_UNAVAIL, PROG_MISMATCH,
// PROG_UNAVAIL), or close the connection only where libtirpc is known to (a call in several
// fragments, a record past the size limit, an RPC version other than 2). A SUCCESS body must
// decode with the procedure's rpcgen result routine, to its last byte, with ff_status values in
// the enum (FF_INTERNAL_ERROR, an exception in a handler, counts as a failure). Every few hundred
// cases a normal client must still get the embedded engine's answers, and at the end footfalld's
// memory must not have grown. Named cases below pin what the sweep relies on.
//
// The sweep is deterministic: each case draws from its own seed (in every failure message);
// FOOTFALL_FUZZ_CASES=N runs N cases instead of the default, FOOTFALL_FUZZ_SEED=S another sweep,
// FOOTFALL_FUZZ_TRACE=1 prints every call and its answer, FOOTFALL_FUZZ_RSS=1 the server's
// memory every 1000 cases.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall.h"
#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "server_process.h"

using namespace footfall;
using footfall::test::ServerProcess;

namespace {

using Bytes = std::vector<unsigned char>;

// Cases in the sweep: 12000 (about 2 s), or FOOTFALL_FUZZ_CASES for a longer search.
int FuzzCases() {
  const char* cases = std::getenv("FOOTFALL_FUZZ_CASES");
  return cases && std::atoi(cases) > 0 ? std::atoi(cases) : 12000;
}

uint64_t FuzzSeed() {
  const char* seed = std::getenv("FOOTFALL_FUZZ_SEED");
  return seed && *seed ? std::strtoull(seed, nullptr, 10) : 20261204u;
}

// [Units: s] How long a reply may take. Queries are answered in milliseconds; a server-side load
// of the small files here (its reply held until it is built) in well under a second.
constexpr double kReplyTimeoutS = 5;

// Cases between two checks that a normal client is served correctly.
constexpr int kHealthEvery = 250;

// --- bytes on the wire -------------------------------------------------------------------------

void Put32(Bytes* b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b->push_back(static_cast<unsigned char>(v >> s));
}

uint32_t Get32(const unsigned char* p) {
  return uint32_t{p[0]} << 24 | uint32_t{p[1]} << 16 | uint32_t{p[2]} << 8 | p[3];
}

void Set32(Bytes* b, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + i] = static_cast<unsigned char>(v >> (24 - 8 * i));
}

void Set64(Bytes* b, size_t at, uint64_t v) {
  Set32(b, at, static_cast<uint32_t>(v >> 32));
  Set32(b, at + 4, static_cast<uint32_t>(v));
}

std::string Hex(const Bytes& b, size_t max = 96) {
  std::string out;
  char two[4];
  for (size_t i = 0; i < b.size() && i < max; ++i) {
    std::snprintf(two, sizeof two, "%02x", b[i]);
    out += two;
    if (i % 4 == 3) out += ' ';
  }
  return out + (b.size() > max ? "..." : "");
}

// Encodes `value` with an rpcgen xdr_* routine.
template <typename T>
Bytes Encode(xdrproc_t proc, T* value) {
  Bytes buffer(FF_MAX_REQUEST_BYTES);
  XDR x;
  xdrmem_create(&x, reinterpret_cast<char*>(buffer.data()), static_cast<u_int>(buffer.size()),
                XDR_ENCODE);
  const bool ok = proc(&x, value) != 0;
  const u_int used = xdr_getpos(&x);
  xdr_destroy(&x);
  if (!ok) throw std::runtime_error("rpcgen could not encode a seed value");
  buffer.resize(used);
  return buffer;
}

// Decodes `bytes` into *value with an rpcgen xdr_* routine; *used: the bytes it read. The caller
// frees *value with xdr_free (also after a failure: rpcgen leaves what it allocated).
template <typename T>
bool Decode(xdrproc_t proc, const Bytes& bytes, T* value, size_t* used = nullptr) {
  std::memset(static_cast<void*>(value), 0, sizeof *value);
  XDR x;
  xdrmem_create(&x, reinterpret_cast<char*>(const_cast<unsigned char*>(bytes.data())),
                static_cast<u_int>(bytes.size()), XDR_DECODE);
  const bool ok = proc(&x, value) != 0;
  if (used) *used = xdr_getpos(&x);
  xdr_destroy(&x);
  return ok;
}

template <typename T>
void Free(xdrproc_t proc, T* value) {
  xdr_free(proc, reinterpret_cast<char*>(value));
}

#define FF_XDR(name) reinterpret_cast<xdrproc_t>(xdr_##name)

bool ValidStatus(int status) { return status >= FF_OK && status <= FF_INTERNAL_ERROR; }

// --- where the fields of an encoded value are, for targeted damage -----------------------------

enum class Field { kWord, kCount, kDouble, kHyper };

struct Layout {
  std::vector<std::pair<size_t, Field>> fields;  // offset, kind
  size_t size = 0;                               // bytes of the whole value
  void Word() { Add(Field::kWord, 4); }
  void Count() { Add(Field::kCount, 4); }
  void Double() { Add(Field::kDouble, 8); }
  void Hyper() { Add(Field::kHyper, 8); }
  void Vec() { Double(), Double(), Double(); }
  void String(size_t length) {
    Count();
    size += (length + 3) & ~size_t{3};
  }
  void Add(Field f, size_t bytes) {
    fields.emplace_back(size, f);
    size += bytes;
  }
};

// Valid arguments of one call, as rpcgen encodes them, and where their fields are.
struct Seed {
  Bytes bytes;
  Layout layout;
};

// --- a deterministic generator -----------------------------------------------------------------

class Rng {
 public:
  explicit Rng(uint64_t seed) : rng_(seed) {}
  size_t Below(size_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(rng_);
  }
  bool Chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
  double Real(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  uint32_t U32() { return static_cast<uint32_t>(rng_()); }
  uint64_t U64() { return rng_(); }
  template <typename T, size_t N>
  T Pick(const T (&list)[N]) {
    return list[Below(N)];
  }

 private:
  std::mt19937_64 rng_;
};

// --- what the fuzzing connection knows --------------------------------------------------------

struct Context {
  uint32_t main_terrain = 0;            // the normal client's terrain: never unloaded by the fuzz
  std::vector<uint32_t> uploads;        // begun on the current connection
  std::map<uint32_t, uint64_t> unsent;  // by upload: samples announced and not yet sent
  std::vector<uint32_t> terrains;       // loaded on the current connection
};

uint32_t PickTerrain(Rng& r, const Context& c) {
  const size_t roll = r.Below(20);
  if (roll < 13) return c.main_terrain;
  if (roll < 16 && !c.terrains.empty()) return c.terrains[r.Below(c.terrains.size())];
  if (roll < 19) return r.U32() % 8 == 0 ? 0 : r.U32();
  return c.main_terrain + 1;
}

uint32_t PickUpload(Rng& r, const Context& c) {
  if (!c.uploads.empty() && r.Chance(0.85)) return c.uploads[r.Below(c.uploads.size())];
  return r.Chance(0.5) ? r.U32() % 64 : r.U32();
}

ff_vec3 NearPoint(Rng& r) {
  ff_vec3 p{r.Real(-2, 12), r.Real(-2, 4), r.Real(-2, 12)};
  if (r.Chance(0.05)) p = {p.x * 1000, p.y * 1000, p.z * 1000};
  return p;
}

ff_vec3 Direction(Rng& r) {
  if (r.Chance(0.05)) return {0, 0, 0};
  return {r.Real(-1, 1), r.Real(-0.2, 0.2), r.Real(-1, 1)};
}

// How many items a batch or chunk seed carries: mostly a few, sometimes a full protocol batch.
u_int Items(Rng& r, u_int max) {
  const size_t roll = r.Below(40);
  if (roll == 0) return 0;
  if (roll == 1) return max;
  if (roll < 5) return static_cast<u_int>(1 + r.Below(max));
  return static_cast<u_int>(1 + r.Below(24));
}

const char* const kPaths[] = {
    "corner.obj",  "flat.pts",        "hill.asc", "corner.obj", "missing.obj", "../outside.pts",
    "/etc/passwd", "sub/../flat.pts", "",         "flat.pts\n", "hill.asc",    "bad.obj"};

// --- the procedures ----------------------------------------------------------------------------

// What a SUCCESS reply body says, checked; "" when it is well formed. May record handles in the
// context (uploads begun, terrains loaded).
using ResultCheck = std::function<std::string(const Bytes& args, const Bytes& body, Context*)>;

struct Procedure {
  uint32_t number;
  const char* name;
  std::function<Seed(Rng&, const Context&)> make;  // valid arguments
  xdrproc_t args_xdr;                              // nullptr: void
  size_t args_size;                                // sizeof the rpcgen argument type
  ResultCheck check;
};

// Decodes a SUCCESS body with the result routine: it must decode, to its last byte.
template <typename T>
std::string DecodeWhole(xdrproc_t proc, const Bytes& body, T* value) {
  size_t used = 0;
  if (!Decode(proc, body, value, &used)) {
    Free(proc, value);
    return "the SUCCESS body does not decode as the procedure's result";
  }
  if (used != body.size()) {
    Free(proc, value);
    return "the SUCCESS body has " + std::to_string(body.size() - used) +
           " bytes past the procedure's result";
  }
  return "";
}

// A reply that carries a status as its first field. FF_INTERNAL_ERROR is a failure too: footfalld
// answers it only for an exception in a handler, and input from a socket must be validated and
// answered with the status that names what is wrong with it, not throw.
std::string CheckStatus(int status) {
  if (!ValidStatus(status)) return "status " + std::to_string(status) + " is not an ff_status";
  if (status == FF_INTERNAL_ERROR) return "FF_INTERNAL_ERROR (an exception in a handler)";
  return "";
}

// `note` sees each reply with the arguments sent (which decode: the answer was SUCCESS).
template <typename T>
ResultCheck StatusResult(xdrproc_t proc,
                         std::function<void(const T&, const Bytes&, Context*)> note = nullptr) {
  return [proc, note](const Bytes& args, const Bytes& body, Context* c) {
    T value;
    std::string problem = DecodeWhole(proc, body, &value);
    if (!problem.empty()) return problem;
    problem = CheckStatus(static_cast<int>(value.status));
    if (problem.empty() && note) note(value, args, c);
    Free(proc, &value);
    return problem;
  };
}

// Batch replies: on FF_OK one result per query sent, each with an ff_status; else no results.
template <typename Args>
ResultCheck BatchResult(xdrproc_t args_proc, std::function<u_int(const Args&)> count) {
  return [args_proc, count](const Bytes& args, const Bytes& body, Context*) {
    ff_batch_reply reply;
    std::string problem = DecodeWhole(FF_XDR(ff_batch_reply), body, &reply);
    if (!problem.empty()) return problem;
    problem = CheckStatus(reply.status);
    Args sent;
    const bool decoded = Decode(args_proc, args, &sent);
    const u_int queries = decoded ? count(sent) : 0;
    Free(args_proc, &sent);
    if (problem.empty() && reply.status == FF_OK && reply.results.results_len != queries)
      problem = std::to_string(reply.results.results_len) + " results for " +
                std::to_string(queries) + " queries";
    if (problem.empty() && reply.status != FF_OK && reply.results.results_len != 0)
      problem = "results with a failed batch";
    for (u_int i = 0; problem.empty() && i < reply.results.results_len; ++i) {
      const std::string item = CheckStatus(reply.results.results_val[i].status);
      if (!item.empty()) problem = "result " + std::to_string(i) + ": " + item;
    }
    Free(FF_XDR(ff_batch_reply), &reply);
    return problem;
  };
}

std::vector<Procedure> Procedures() {
  std::vector<Procedure> p;
  auto none = [](Rng&, const Context&) { return Seed{}; };
  p.push_back({FF_NULL, "FF_NULL", none, nullptr, 0, [](const Bytes&, const Bytes& body, Context*) {
                 return body.empty() ? std::string() : "FF_NULL answered a body";
               }});
  p.push_back({FF_LOAD, "FF_LOAD",
               [](Rng& r, const Context&) {
                 ff_load_args a{};
                 a.path = const_cast<char*>(r.Pick(kPaths));
                 a.separation = r.Pick({0.0, 0.1, 0.25, 0.5, -1.0});
                 Seed s{Encode(FF_XDR(ff_load_args), &a), {}};
                 s.layout.String(std::strlen(a.path)), s.layout.Double();
                 return s;
               },
               FF_XDR(ff_load_args), sizeof(ff_load_args),
               StatusResult<ff_load_reply>(FF_XDR(ff_load_reply),
                                           [](const ff_load_reply& v, const Bytes&, Context* c) {
                                             if (v.status == FF_OK)
                                               c->terrains.push_back(v.terrain);
                                           })});
  p.push_back(
      {FF_UPLOAD_BEGIN, "FF_UPLOAD_BEGIN",
       [](Rng& r, const Context&) {
         std::string name = "fuzz";
         for (size_t i = 0, n = r.Below(12); i < n; ++i)
           name += static_cast<char>('a' + r.Below(26));
         ff_upload_begin_args a{};
         a.name = name.data();
         a.total = r.Chance(0.05) ? 0 : 1 + r.Below(r.Chance(0.8) ? 16 : 200);
         Seed s{Encode(FF_XDR(ff_upload_begin_args), &a), {}};
         s.layout.String(name.size()), s.layout.Hyper();
         return s;
       },
       FF_XDR(ff_upload_begin_args), sizeof(ff_upload_begin_args),
       StatusResult<ff_upload_reply>(FF_XDR(ff_upload_reply),
                                     [](const ff_upload_reply& v, const Bytes& args, Context* c) {
                                       if (v.status != FF_OK) return;
                                       ff_upload_begin_args a;
                                       Decode(FF_XDR(ff_upload_begin_args), args, &a);
                                       c->uploads.push_back(v.upload);
                                       c->unsent[v.upload] = a.total;
                                       Free(FF_XDR(ff_upload_begin_args), &a);
                                     })});
  p.push_back(
      {FF_UPLOAD_CHUNK, "FF_UPLOAD_CHUNK",
       [](Rng& r, const Context& c) {
         // Mostly the next samples of an upload begun (all that are left, or some).
         std::vector<ff_sample> samples(Items(r, 256));
         uint32_t upload = PickUpload(r, c);
         for (const auto& [id, unsent] : c.unsent)
           if (unsent > 0 && r.Chance(0.9)) upload = id;
         const auto open = c.unsent.find(upload);
         if (open != c.unsent.end() && open->second > 0 && r.Chance(0.9))
           samples.resize(
               std::min<uint64_t>(r.Chance(0.7) ? open->second : 1 + r.Below(open->second), 256));
         for (ff_sample& s : samples) {
           s.point = {r.Real(0, 4), r.Real(-0.1, 0.1), r.Real(0, 4)};
           s.normal = {r.Real(-0.1, 0.1), 1, r.Real(-0.1, 0.1)};
         }
         ff_upload_chunk_args a{};
         a.upload = upload;
         a.samples.samples_len = static_cast<u_int>(samples.size());
         a.samples.samples_val = samples.data();
         Seed s{Encode(FF_XDR(ff_upload_chunk_args), &a), {}};
         s.layout.Word(), s.layout.Count();
         for (size_t i = 0; i < samples.size(); ++i) s.layout.Vec(), s.layout.Vec();
         return s;
       },
       FF_XDR(ff_upload_chunk_args), sizeof(ff_upload_chunk_args),
       StatusResult<ff_status_reply>(FF_XDR(ff_status_reply),
                                     [](const ff_status_reply& v, const Bytes& args, Context* c) {
                                       if (v.status != FF_OK) return;
                                       ff_upload_chunk_args a;
                                       Decode(FF_XDR(ff_upload_chunk_args), args, &a);
                                       uint64_t& unsent = c->unsent[a.upload];
                                       unsent -= std::min<uint64_t>(unsent, a.samples.samples_len);
                                       Free(FF_XDR(ff_upload_chunk_args), &a);
                                     })});
  p.push_back(
      {FF_UPLOAD_FINISH, "FF_UPLOAD_FINISH",
       [](Rng& r, const Context& c) {
         // Mostly an upload whose samples are all sent.
         ff_upload_args a{PickUpload(r, c)};
         for (const auto& [upload, unsent] : c.unsent)
           if (unsent == 0 && r.Chance(0.8)) a.upload = upload;
         Seed s{Encode(FF_XDR(ff_upload_args), &a), {}};
         s.layout.Word();
         return s;
       },
       FF_XDR(ff_upload_args), sizeof(ff_upload_args),
       StatusResult<ff_load_reply>(
           FF_XDR(ff_load_reply), [](const ff_load_reply& v, const Bytes& args, Context* c) {
             if (v.status == FF_OK) c->terrains.push_back(v.terrain);
             if (v.status == FF_UNAVAILABLE) return;  // busy: it may be finished later
             ff_upload_args a;
             Decode(FF_XDR(ff_upload_args), args, &a);
             c->unsent.erase(a.upload);  // built, or refused and dropped
             c->uploads.erase(std::remove(c->uploads.begin(), c->uploads.end(), a.upload),
                              c->uploads.end());
           })});
  auto terrain_args = [](Rng& r, const Context& c) {
    ff_terrain_args a{PickTerrain(r, c)};
    Seed s{Encode(FF_XDR(ff_terrain_args), &a), {}};
    s.layout.Word();
    return s;
  };
  p.push_back({FF_INFO, "FF_INFO", terrain_args, FF_XDR(ff_terrain_args), sizeof(ff_terrain_args),
               StatusResult<ff_info_reply>(FF_XDR(ff_info_reply))});
  p.push_back({FF_UNLOAD, "FF_UNLOAD",
               [](Rng& r, const Context& c) {
                 // Its own terrains, or others' (refused: only the loader or an orphan's
                 // finder may unload; the main terrain's client is connected throughout).
                 ff_terrain_args a{!c.terrains.empty() && r.Chance(0.5)
                                       ? c.terrains[r.Below(c.terrains.size())]
                                       : PickTerrain(r, c)};
                 Seed s{Encode(FF_XDR(ff_terrain_args), &a), {}};
                 s.layout.Word();
                 return s;
               },
               FF_XDR(ff_terrain_args), sizeof(ff_terrain_args),
               StatusResult<ff_status_reply>(FF_XDR(ff_status_reply))});
  p.push_back(
      {FF_LIST, "FF_LIST", none, nullptr, 0, [](const Bytes&, const Bytes& body, Context* c) {
         ff_list_reply v;
         std::string problem = DecodeWhole(FF_XDR(ff_list_reply), body, &v);
         if (!problem.empty()) return problem;
         problem = CheckStatus(v.status);
         bool main = false;
         for (u_int i = 0; i < v.terrains.terrains_len; ++i)
           main = main || v.terrains.terrains_val[i] == c->main_terrain;
         if (problem.empty() && !main) problem = "FF_LIST lacks the main terrain";
         Free(FF_XDR(ff_list_reply), &v);
         return problem;
       }});
  auto point_args = [](Rng& r, const Context& c) {
    ff_point_args a{PickTerrain(r, c), NearPoint(r)};
    Seed s{Encode(FF_XDR(ff_point_args), &a), {}};
    s.layout.Word(), s.layout.Vec();
    return s;
  };
  p.push_back({FF_SNAP, "FF_SNAP", point_args, FF_XDR(ff_point_args), sizeof(ff_point_args),
               StatusResult<ff_result>(FF_XDR(ff_result))});
  p.push_back({FF_NORMAL, "FF_NORMAL", point_args, FF_XDR(ff_point_args), sizeof(ff_point_args),
               StatusResult<ff_result>(FF_XDR(ff_result))});
  p.push_back(
      {FF_NEXT, "FF_NEXT",
       [](Rng& r, const Context& c) {
         ff_next_args a{
             PickTerrain(r, c), r.Pick({0.0, 0.0, 0.2, -1.0, 3.0}), {NearPoint(r), Direction(r)}};
         Seed s{Encode(FF_XDR(ff_next_args), &a), {}};
         s.layout.Word(), s.layout.Double(), s.layout.Vec(), s.layout.Vec();
         return s;
       },
       FF_XDR(ff_next_args), sizeof(ff_next_args), StatusResult<ff_result>(FF_XDR(ff_result))});
  auto point_batch = [](Rng& r, const Context& c) {
    std::vector<ff_vec3> points(Items(r, FF_MAX_BATCH));
    for (ff_vec3& v : points) v = NearPoint(r);
    ff_point_batch_args a{};
    a.terrain = PickTerrain(r, c);
    a.points.points_len = static_cast<u_int>(points.size());
    a.points.points_val = points.data();
    Seed s{Encode(FF_XDR(ff_point_batch_args), &a), {}};
    s.layout.Word(), s.layout.Count();
    for (size_t i = 0; i < points.size(); ++i) s.layout.Vec();
    return s;
  };
  const ResultCheck point_batch_result = BatchResult<ff_point_batch_args>(
      FF_XDR(ff_point_batch_args),
      [](const ff_point_batch_args& a) { return a.points.points_len; });
  p.push_back({FF_SNAP_BATCH, "FF_SNAP_BATCH", point_batch, FF_XDR(ff_point_batch_args),
               sizeof(ff_point_batch_args), point_batch_result});
  p.push_back({FF_NORMAL_BATCH, "FF_NORMAL_BATCH", point_batch, FF_XDR(ff_point_batch_args),
               sizeof(ff_point_batch_args), point_batch_result});
  p.push_back(
      {FF_NEXT_BATCH, "FF_NEXT_BATCH",
       [](Rng& r, const Context& c) {
         std::vector<ff_next_query> queries(Items(r, FF_MAX_BATCH));
         for (ff_next_query& q : queries) q = {NearPoint(r), Direction(r)};
         ff_next_batch_args a{};
         a.terrain = PickTerrain(r, c);
         a.tolerance = r.Pick({0.0, 0.0, 0.2, -1.0, 3.0});
         a.queries.queries_len = static_cast<u_int>(queries.size());
         a.queries.queries_val = queries.data();
         Seed s{Encode(FF_XDR(ff_next_batch_args), &a), {}};
         s.layout.Word(), s.layout.Double(), s.layout.Count();
         for (size_t i = 0; i < queries.size(); ++i) s.layout.Vec(), s.layout.Vec();
         return s;
       },
       FF_XDR(ff_next_batch_args), sizeof(ff_next_batch_args),
       BatchResult<ff_next_batch_args>(FF_XDR(ff_next_batch_args), [](const ff_next_batch_args& a) {
         return a.queries.queries_len;
       })});
  p.push_back({FF_RECENT, "FF_RECENT",
               [](Rng& r, const Context&) {
                 ff_recent_args a{r.Chance(0.3) ? 0 : r.Below(20000)};
                 Seed s{Encode(FF_XDR(ff_recent_args), &a), {}};
                 s.layout.Hyper();
                 return s;
               },
               FF_XDR(ff_recent_args), sizeof(ff_recent_args),
               [](const Bytes&, const Bytes& body, Context*) {
                 ff_recent_reply v;
                 std::string problem = DecodeWhole(FF_XDR(ff_recent_reply), body, &v);
                 if (!problem.empty()) return problem;
                 problem = CheckStatus(v.status);
                 for (u_int i = 0; problem.empty() && i < v.queries.queries_len; ++i) {
                   const ff_recent_query& q = v.queries.queries_val[i];
                   if (q.op < FF_OP_SNAP || q.op > FF_OP_NEXT)
                     problem = "recent query " + std::to_string(i) + ": op " +
                               std::to_string(q.op) + " is not an ff_op";
                   else if (!CheckStatus(q.result.status).empty())
                     problem =
                         "recent query " + std::to_string(i) + ": " + CheckStatus(q.result.status);
                   else if (q.sequence > v.latest)
                     problem = "recent query past the latest sequence";
                 }
                 Free(FF_XDR(ff_recent_reply), &v);
                 return problem;
               }});
  p.push_back(
      {FF_LOAD_OPTIONS, "FF_LOAD_OPTIONS",
       [](Rng& r, const Context&) {
         ff_load_options_args a{};
         a.path = const_cast<char*>(r.Pick(kPaths));
         a.separation = r.Pick({0.0, 0.1, 0.25, 0.5});
         a.finest_default = r.Pick({0.0, 0.1, 0.3});
         a.smooth_normals = r.Chance(0.5);
         a.crease_angle_deg = r.Pick({0.0, 30.0, 60.0, 180.0});
         a.seed = r.U64();
         const int axes[] = {'y', 'y', 'x', 'z', 'q', 0};
         a.up_axis = r.Pick(axes);
         a.cell_size = r.Pick({0.0, 0.0, 0.5, 2.0});
         a.height_scale = r.Pick({0.0, 1.0, 2.5});
         a.max_samples = r.Pick({uint64_t{0}, uint64_t{0}, uint64_t{1000}, uint64_t{50000}});
         Seed s{Encode(FF_XDR(ff_load_options_args), &a), {}};
         Layout& l = s.layout;
         l.String(std::strlen(a.path)), l.Double(), l.Double(), l.Word(), l.Double(), l.Hyper();
         l.Word(), l.Double(), l.Double(), l.Hyper();
         return s;
       },
       FF_XDR(ff_load_options_args), sizeof(ff_load_options_args),
       StatusResult<ff_load_reply>(FF_XDR(ff_load_reply),
                                   [](const ff_load_reply& v, const Bytes&, Context* c) {
                                     if (v.status == FF_OK) c->terrains.push_back(v.terrain);
                                   })});
  p.push_back({FF_ASK_AGAIN, "FF_ASK_AGAIN", none, nullptr, 0,
               StatusResult<ff_status_reply>(FF_XDR(ff_status_reply))});
  return p;
}

// True when rpcgen's routine decodes `args` as the procedure's arguments (void always does:
// bytes after the arguments are not read).
bool ArgsDecode(const Procedure& p, const Bytes& args) {
  if (!p.args_xdr) return true;
  alignas(16) unsigned char storage[256];
  REQUIRE(p.args_size <= sizeof storage);
  std::memset(storage, 0, sizeof storage);
  XDR x;
  xdrmem_create(&x, reinterpret_cast<char*>(const_cast<unsigned char*>(args.data())),
                static_cast<u_int>(args.size()), XDR_DECODE);
  const bool ok = p.args_xdr(&x, storage) != 0;
  xdr_destroy(&x);
  xdr_free(p.args_xdr, reinterpret_cast<char*>(storage));
  return ok;
}

// --- damage ----------------------------------------------------------------------------------

const uint32_t kWords[] = {0, 1, 0xffffffffu, 0x7fffffffu, 0x80000000u, 0xfffffffeu};
const uint32_t kCounts[] = {0xffffffffu, 0x80000000u, 0x7fffffffu,  0xfffffffeu, 1u << 30,
                            65536,       4097,        FF_MAX_BATCH, 257,         1025};
const double kDoubles[] = {std::numeric_limits<double>::quiet_NaN(),
                           -std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           1e308,
                           -1e308,
                           -0.0,
                           4.9e-324,
                           1e-300,
                           5e14,
                           -4.9e14,
                           1e15};
const uint64_t kHypers[] = {
    0, 1, ~uint64_t{0}, uint64_t{1} << 63, uint64_t{1} << 32, uint64_t{1} << 28};

// A field of kind `f` in the layout (within `size` bytes), or none.
bool PickField(Rng& r, const Layout& l, Field f, size_t size, size_t* at) {
  std::vector<size_t> offsets;
  for (const auto& [offset, kind] : l.fields)
    if (kind == f && offset + (f == Field::kDouble || f == Field::kHyper ? 8 : 4) <= size)
      offsets.push_back(offset);
  if (offsets.empty()) return false;
  *at = offsets[r.Below(offsets.size())];
  return true;
}

// Applies one mutation to *b and says which.
std::string Mutate(Rng& r, const Layout& l, Bytes* b) {
  size_t at = 0;
  switch (r.Below(11)) {
    case 0:
      if (PickField(r, l, Field::kCount, b->size(), &at)) {
        const uint32_t old = Get32(b->data() + at);
        const uint32_t count = r.Chance(0.3) ? old + static_cast<uint32_t>(r.Below(3)) - 1
                                             : r.Pick(kCounts);  // one more or less, or huge
        Set32(b, at, count);
        return "count at " + std::to_string(at) + " := " + std::to_string(count);
      }
      break;
    case 1:
    case 2:
      if (PickField(r, l, Field::kDouble, b->size(), &at)) {
        const double d = r.Pick(kDoubles);
        uint64_t bits;
        std::memcpy(&bits, &d, 8);
        Set64(b, at, bits);
        return "double at " + std::to_string(at) + " := " + std::to_string(d);
      }
      break;
    case 3:
      if (PickField(r, l, Field::kHyper, b->size(), &at)) {
        const uint64_t h = r.Pick(kHypers);
        Set64(b, at, h);
        return "hyper at " + std::to_string(at) + " := " + std::to_string(h);
      }
      break;
    case 4:
      if (b->size() >= 4) {
        at = r.Below(b->size() / 4) * 4;
        const uint32_t w = r.Pick(kWords);
        Set32(b, at, w);
        return "word at " + std::to_string(at) + " := " + std::to_string(w);
      }
      break;
    case 5: {
      const size_t keep = r.Chance(0.5) ? r.Below(b->size() + 1) : r.Below(b->size() / 4 + 1) * 4;
      b->resize(std::min(keep, b->size()));
      return "cut to " + std::to_string(b->size()) + " bytes";
    }
    case 6: {
      size_t n = 1 + r.Below(64);
      // Now and then to about the largest request footfalld takes, or a little past it.
      if (r.Chance(0.02) && b->size() < FF_MAX_REQUEST_BYTES)
        n = FF_MAX_REQUEST_BYTES - b->size() + r.Below(16384);
      for (size_t i = 0; i < n; ++i) b->push_back(static_cast<unsigned char>(r.U32()));
      return "extended by " + std::to_string(n) + " junk bytes";
    }
    case 7: {
      const size_t n = 1 + r.Below(12);
      const size_t where = r.Below(b->size() + 1);
      for (size_t i = 0; i < n; ++i)
        b->insert(b->begin() + static_cast<ptrdiff_t>(where), static_cast<unsigned char>(r.U32()));
      return "inserted " + std::to_string(n) + " bytes at " + std::to_string(where);
    }
    case 8:
      if (!b->empty()) {
        const size_t where = r.Below(b->size());
        const size_t n = std::min(b->size() - where, 1 + r.Below(16));
        b->erase(b->begin() + static_cast<ptrdiff_t>(where),
                 b->begin() + static_cast<ptrdiff_t>(where + n));
        return "deleted " + std::to_string(n) + " bytes at " + std::to_string(where);
      }
      break;
    case 9:
      if (!b->empty()) {
        at = r.Below(b->size());
        const unsigned char v = r.Pick({0x00, 0xff, 0x7f, 0x80});
        (*b)[at] = v;
        return "byte at " + std::to_string(at) + " := " + std::to_string(v);
      }
      break;
    default:
      break;
  }
  if (b->empty()) return "nothing to flip";
  const size_t n = 1 + r.Below(4);
  for (size_t i = 0; i < n; ++i)
    (*b)[r.Below(b->size())] ^= static_cast<unsigned char>(1u << r.Below(8));
  return "flipped " + std::to_string(n) + " bits";
}

// --- calls and replies -------------------------------------------------------------------------

struct Call {
  uint32_t xid = 0, rpcvers = 2, prog = FOOTFALL_PROG, vers = FOOTFALL_V1, proc = 0;
  Bytes args;
  int fragments = 1;
  std::string how;  // for failure messages
};

// The call message (RFC 5531: xid, CALL, RPC version, program, version, procedure, AUTH_NONE
// credentials and verifier, arguments), with record marking: one fragment, or `fragments`
// fragments cut at random places (empty ones included), the last marked as such.
Bytes Record(Rng& r, const Call& c) {
  Bytes body;
  Put32(&body, c.xid), Put32(&body, 0), Put32(&body, c.rpcvers);
  Put32(&body, c.prog), Put32(&body, c.vers), Put32(&body, c.proc);
  Put32(&body, 0), Put32(&body, 0), Put32(&body, 0), Put32(&body, 0);
  body.insert(body.end(), c.args.begin(), c.args.end());
  std::vector<size_t> cuts;
  for (int i = 1; i < c.fragments; ++i) cuts.push_back(r.Below(body.size() + 1));
  std::sort(cuts.begin(), cuts.end());
  cuts.push_back(body.size());
  Bytes record;
  size_t from = 0;
  for (size_t i = 0; i < cuts.size(); ++i) {
    const bool last = i + 1 == cuts.size();
    Put32(&record, (last ? 0x80000000u : 0) | static_cast<uint32_t>(cuts[i] - from));
    record.insert(record.end(), body.begin() + static_cast<ptrdiff_t>(from),
                  body.begin() + static_cast<ptrdiff_t>(cuts[i]));
    from = cuts[i];
  }
  return record;
}

int Connect(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  REQUIRE(fd >= 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  const timeval wait{static_cast<time_t>(kReplyTimeoutS), 0};
  setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &wait, sizeof wait);
  return fd;
}

// Sends everything; false when the server has closed the connection (or it stays full past the
// send timeout).
bool SendAll(int fd, const Bytes& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    sent += static_cast<size_t>(n);
  }
  return true;
}

// kClosed: the connection ended before a whole reply (at EOF or a reset, before its first byte
// or within it); kBadFraming: a reply record larger than any footfalld sends.
enum class Got { kReply, kClosed, kTimeout, kBadFraming };

// Reads `n` bytes before `deadline`.
Got ReadExactly(int fd, unsigned char* out, size_t n,
                std::chrono::steady_clock::time_point deadline) {
  size_t got = 0;
  while (got < n) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return Got::kTimeout;
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return Got::kTimeout;
    const ssize_t k = recv(fd, out + got, n - got, 0);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return Got::kClosed;
    got += static_cast<size_t>(k);
  }
  return Got::kReply;
}

// Reads one reply record (all its fragments).
Got ReadRecord(int fd, Bytes* record) {
  record->clear();
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<int>(kReplyTimeoutS * 1000));
  for (;;) {
    unsigned char mark[4];
    const Got g = ReadExactly(fd, mark, 4, deadline);
    if (g != Got::kReply) return g;
    const uint32_t m = Get32(mark);
    const size_t length = m & 0x7fffffffu;
    if (record->size() + length > 4 * FF_MAX_REQUEST_BYTES) return Got::kBadFraming;
    const size_t at = record->size();
    record->resize(at + length);
    const Got body = ReadExactly(fd, record->data() + at, length, deadline);
    if (body != Got::kReply) return body;
    if (m & 0x80000000u) return Got::kReply;
  }
}

// The reply RFC 5531 and libtirpc give a call.
enum class Answer {
  kSuccess,
  kProgUnavail,
  kProgMismatch,
  kProcUnavail,
  kGarbageArgs,
  kSystemErr,
  kRpcMismatch,
  kAuthError
};

const char* Name(Answer a) {
  switch (a) {
    case Answer::kSuccess:
      return "SUCCESS";
    case Answer::kProgUnavail:
      return "PROG_UNAVAIL";
    case Answer::kProgMismatch:
      return "PROG_MISMATCH";
    case Answer::kProcUnavail:
      return "PROC_UNAVAIL";
    case Answer::kGarbageArgs:
      return "GARBAGE_ARGS";
    case Answer::kSystemErr:
      return "SYSTEM_ERR";
    case Answer::kRpcMismatch:
      return "RPC_MISMATCH";
    case Answer::kAuthError:
      return "AUTH_ERROR";
  }
  return "?";
}

// Parses a reply record to `xid`: its answer, and for SUCCESS the result bytes in *body.
// Returns what is malformed, or "".
std::string ParseReply(const Bytes& rec, uint32_t xid, Answer* answer, Bytes* body) {
  size_t at = 0;
  auto word = [&](uint32_t* v) {
    if (at + 4 > rec.size()) return false;
    *v = Get32(rec.data() + at);
    at += 4;
    return true;
  };
  uint32_t got_xid, type, stat;
  if (!word(&got_xid) || !word(&type) || !word(&stat)) return "reply shorter than its header";
  if (got_xid != xid) return "reply to xid " + std::to_string(got_xid);
  if (type != 1) return "message type " + std::to_string(type) + ", not REPLY";
  auto rest_is = [&](size_t words) -> std::string {
    if (rec.size() != at + 4 * words) return "reply of " + std::to_string(rec.size()) + " bytes";
    return "";
  };
  if (stat == 1) {  // MSG_DENIED
    uint32_t reject, low = 0, high = 0;
    if (!word(&reject)) return "denied reply without its reason";
    if (reject == 0) {
      *answer = Answer::kRpcMismatch;
      if (!word(&low) || !word(&high) || low != 2 || high != 2) return "RPC_MISMATCH not 2..2";
      return rest_is(0);
    }
    if (reject == 1) {
      *answer = Answer::kAuthError;
      return rest_is(1);
    }
    return "reject_stat " + std::to_string(reject);
  }
  if (stat != 0) return "reply_stat " + std::to_string(stat);
  uint32_t flavor, length, accept;
  if (!word(&flavor) || !word(&length)) return "accepted reply without a verifier";
  if (flavor != 0 || length != 0) return "verifier not AUTH_NONE";
  if (!word(&accept)) return "accepted reply without accept_stat";
  switch (accept) {
    case 0:
      *answer = Answer::kSuccess;
      body->assign(rec.begin() + static_cast<ptrdiff_t>(at), rec.end());
      return "";
    case 1:
      *answer = Answer::kProgUnavail;
      return rest_is(0);
    case 2: {
      *answer = Answer::kProgMismatch;
      uint32_t low, high;
      if (!word(&low) || !word(&high)) return "PROG_MISMATCH without its versions";
      if (low != FOOTFALL_V1 || high != FOOTFALL_V1) return "PROG_MISMATCH not 1..1";
      return rest_is(0);
    }
    case 3:
      *answer = Answer::kProcUnavail;
      return rest_is(0);
    case 4:
      *answer = Answer::kGarbageArgs;
      return rest_is(0);
    case 5:
      *answer = Answer::kSystemErr;
      return rest_is(0);
    default:
      return "accept_stat " + std::to_string(accept);
  }
}

// --- the sweep -------------------------------------------------------------------------------

// A normal client's terrain, and the embedded engine with the same samples: the reference.
RawSamples FuzzTerrain() {
  RawSamples s = MakeHeightField(40, 40, 0.25, 1.0, 7);
  const RawSamples ball = MakeSphere(400, {5, 2, 5}, 1);
  for (size_t i = 0; i < ball.size(); ++i) s.push_back(ball.points[i], ball.normals[i]);
  return s;
}

void RequireSame(const Foothold& a, const Foothold& b) {
  REQUIRE(static_cast<int>(a.status) == static_cast<int>(b.status));
  REQUIRE(a.index == b.index);
  REQUIRE(a.point == b.point);
  REQUIRE(a.normal == b.normal);
}

// The server is alive, and the normal client gets the embedded engine's answers.
void RequireHealthy(ServerProcess& server, TerrainSession& rpc, TerrainHandle remote,
                    TerrainSession& embedded, TerrainHandle local, uint64_t seed) {
  int status = 0;
  INFO("footfalld log:\n" << server.Log());
  REQUIRE(waitpid(server.pid(), &status, WNOHANG) == 0);
  Rng r(seed);
  std::vector<Vec3> points;
  std::vector<StepQuery> steps;
  for (int i = 0; i < 64; ++i) {
    const ff_vec3 p = NearPoint(r), d = Direction(r);
    points.push_back({p.x, p.y, p.z});
    steps.push_back({{p.x, p.y, p.z}, {d.x, d.y, d.z}});
  }
  std::vector<Foothold> a(points.size()), b(points.size());
  REQUIRE(rpc.Snap(remote, points.data(), points.size(), a.data()) == Status::kOk);
  REQUIRE(embedded.Snap(local, points.data(), points.size(), b.data()) == Status::kOk);
  for (size_t i = 0; i < points.size(); ++i) RequireSame(a[i], b[i]);
  REQUIRE(rpc.Next(remote, steps.data(), steps.size(), 0.2, a.data()) == Status::kOk);
  REQUIRE(embedded.Next(local, steps.data(), steps.size(), 0.2, b.data()) == Status::kOk);
  for (size_t i = 0; i < steps.size(); ++i) RequireSame(a[i], b[i]);
  RequireSame(rpc.Snap(remote, points[0]), embedded.Snap(local, points[0]));
}

// A fresh folder for --data-root with small terrain files of each kind, removed at the end.
struct DataRoot {
  std::string path;
  DataRoot() {
    char tmpl[] = "/tmp/footfall-fuzz-root-XXXXXX";
    REQUIRE(mkdtemp(tmpl));
    path = tmpl;
    std::ofstream(path + "/corner.obj")
        << "v 0 0 0\nv 2 0 0\nv 2 0 2\nv 0 0 2\nv 2 1 0\nv 2 1 2\nf 1 3 2\nf 1 4 3\nf 2 3 6\n"
           "f 2 6 5\n";
    std::ofstream points(path + "/flat.pts");
    for (int i = 0; i < 100; ++i) points << i % 10 << " 0 " << i / 10 << " 0 1 0\n";
    std::ofstream(path + "/hill.asc")
        << "ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n"
           "1 2 3 4\n4 -9999 6 7\n1.5 2.5 -3 0\n";
    std::ofstream(path + "/bad.obj") << "v 0 0 0\nv 1 0 nan\nf 1 2 3\n";  // a parse error
  }
  ~DataRoot() { std::system(("rm -rf '" + path + "'").c_str()); }
  DataRoot(const DataRoot&) = delete;
  DataRoot& operator=(const DataRoot&) = delete;
};

// footfalld for fuzzing: a small sample budget (a damaged count or size can ask for at most
// that), orphans and idle uploads freed after a second (the fuzz connections come and go), and a
// short batch time limit.
std::vector<std::string> FuzzServerArgs(const DataRoot& root) {
  std::vector<std::string> args = {"--no-rpcbind", "--data-root", root.path};
  args.insert(args.end(), {"--max-samples", "20000", "--orphan-timeout", "1"});
  args.insert(args.end(), {"--upload-timeout", "1", "--threads", "2"});
  // Batches are answered in parts, some of their results FF_LIMIT_EXCEEDED.
  args.insert(args.end(), {"--batch-time-limit", "0.0005"});
  return args;
}

// A footfalld for one test case, and a normal client that uploaded the fuzz terrain to it.
struct FuzzServer {
  DataRoot root;
  ServerProcess server{0, FuzzServerArgs(root)};
  std::unique_ptr<TerrainSession> rpc = [this] {
    RpcOptions o;
    o.port = server.port();
    return MakeRpcSession(o);
  }();
  TerrainHandle remote = 0;

  FuzzServer() { REQUIRE(rpc->LoadSamples(FuzzTerrain(), "fuzz", &remote) == Status::kOk); }
};

// The server's handle for the one terrain it holds, through a raw FF_LIST call.
uint32_t OnlyTerrain(int port) {
  const int fd = Connect(port);
  Call call;
  call.xid = 1;
  call.proc = FF_LIST;
  Rng r(1);
  REQUIRE(SendAll(fd, Record(r, call)));
  Bytes rec, body;
  REQUIRE(ReadRecord(fd, &rec) == Got::kReply);
  close(fd);
  Answer answer{};
  REQUIRE(ParseReply(rec, 1, &answer, &body) == "");
  REQUIRE(answer == Answer::kSuccess);
  ff_list_reply list;
  REQUIRE(DecodeWhole(FF_XDR(ff_list_reply), body, &list) == "");
  REQUIRE(list.terrains.terrains_len == 1);
  const uint32_t handle = list.terrains.terrains_val[0];
  Free(FF_XDR(ff_list_reply), &list);
  return handle;
}

// A raw connection for the named cases: one call at a time, its reply required well framed.
struct RawConnection {
  explicit RawConnection(int port) : fd(Connect(port)) {}
  ~RawConnection() { close(fd); }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;
  // Sends `args` to `proc` in `fragments` fragments; false when the server closed the
  // connection instead of answering, else the answer and, for SUCCESS, the result bytes.
  bool Call(uint32_t proc, const Bytes& args, Answer* answer, Bytes* body, int fragments = 1) {
    ::Call c;
    c.xid = xid++;
    c.proc = proc;
    c.args = args;
    c.fragments = fragments;
    Rng r(c.xid);
    if (!SendAll(fd, Record(r, c))) return false;
    Bytes rec;
    const Got got = ReadRecord(fd, &rec);
    REQUIRE(got != Got::kTimeout);
    REQUIRE(got != Got::kBadFraming);
    if (got == Got::kClosed) return false;
    REQUIRE(ParseReply(rec, c.xid, answer, body) == "");
    return true;
  }
  // The status that starts a SUCCESS reply to `proc`.
  int Status(uint32_t proc, const Bytes& args) {
    Answer answer{};
    Bytes body;
    REQUIRE(Call(proc, args, &answer, &body));
    REQUIRE(answer == Answer::kSuccess);
    REQUIRE(body.size() >= 4);
    return static_cast<int>(Get32(body.data()));
  }
  int fd;
  uint32_t xid = 1;
};

// What a call must get: `expect`, or (when `may_close`) a closed connection instead.
struct Expectation {
  Answer expect = Answer::kSuccess;
  bool may_close = false;
  bool may_garble = false;  // GARBAGE_ARGS is allowed too
};

Expectation Expect(const std::vector<Procedure>& procs, const Call& c, size_t record_bytes) {
  Expectation e;
  if (c.rpcvers != 2) {
    // RFC 5531 answers RPC_MISMATCH; libtirpc's xdr_callmsg refuses the header instead, and the
    // connection is closed without a reply.
    e.expect = Answer::kRpcMismatch;
    e.may_close = true;
  } else if (c.prog != FOOTFALL_PROG) {
    e.expect = Answer::kProgUnavail;
  } else if (c.vers != FOOTFALL_V1) {
    e.expect = Answer::kProgMismatch;
  } else if (c.proc >= procs.size()) {
    e.expect = Answer::kProcUnavail;
  } else {
    e.expect = ArgsDecode(procs[c.proc], c.args) ? Answer::kSuccess : Answer::kGarbageArgs;
  }
  if (c.fragments > 1) {
    // Documented in footfall.x (clients must keep each request in one fragment): libtirpc's
    // non-blocking server drops a request sent in several fragments. It answers GARBAGE_ARGS
    // (its arguments come out short) or closes the connection, now or at a later call; it never
    // answers SUCCESS to arguments that do not decode.
    e.may_garble = true;
    e.may_close = true;
  }
  if (record_bytes > FF_MAX_REQUEST_BYTES) {
    // Past the record size the server takes (FF_MAX_REQUEST_BYTES and a margin), libtirpc
    // closes the connection.
    e.may_close = true;
  }
  return e;
}

// What one case found: what went wrong, or ""; whether the server closed the connection (where
// the expectations allowed it).
struct CaseResult {
  std::string problem;
  bool closed = false;
};

// The fuzzing client: one raw connection at a time (a new one now and then, and after the server
// closes one), with what it knows of its uploads and terrains.
struct Sweep {
  const std::vector<Procedure>& procs;
  int port;
  Context context;
  int fd = -1;
  uint32_t xid = 1;
  bool frayed = false;  // a call in several fragments, or too large, was sent on the connection
  const bool trace = std::getenv("FOOTFALL_FUZZ_TRACE") != nullptr;  // every call on stderr
  // Tallies, shown with the result.
  size_t answers[8] = {};
  size_t closes = 0, reconnects = 0, statuses[10] = {};

  void Reconnect() {
    if (trace) std::fprintf(stderr, "new connection\n");
    if (fd >= 0) close(fd);
    fd = Connect(port);
    frayed = false;
    context.uploads.clear();
    context.unsent.clear();
    context.terrains.clear();
    ++reconnects;
  }

  // The calls of case `seed`.
  std::vector<Call> MakeCalls(Rng& r) {
    const size_t count = r.Chance(0.05) ? 2 + r.Below(3) : 1;
    std::vector<Call> calls(count);
    for (Call& c : calls) {
      c.xid = xid++;
      const size_t header = r.Below(100);
      size_t number = r.Below(procs.size());
      // An upload begun is often continued, mostly with valid arguments, so that uploads are
      // finished and built too (a connection lasts a few dozen calls).
      const bool continues = !context.unsent.empty() && r.Chance(0.4);
      if (continues) number = r.Chance(0.7) ? FF_UPLOAD_CHUNK : FF_UPLOAD_FINISH;
      const Procedure& p = procs[number];
      c.proc = p.number;
      if (header < 3) {
        c.proc = r.Pick({17u, 18u, 100u, 0xffffffffu, 0x80000000u, r.U32()});
        c.how = "unknown procedure " + std::to_string(c.proc) + "; ";
      } else if (header < 5) {
        c.vers = r.Pick({0u, 2u, 0xffffffffu, r.U32()});
        c.how = "version " + std::to_string(c.vers) + "; ";
      } else if (header < 6) {
        c.prog = r.Pick({static_cast<uint32_t>(FOOTFALL_PROG) + 1, 0u, 100000u, r.U32()});
        c.how = "program " + std::to_string(c.prog) + "; ";
      } else if (header < 7) {
        c.rpcvers = r.Pick({0u, 1u, 3u, 0xffffffffu});
        c.how = "RPC version " + std::to_string(c.rpcvers) + "; ";
      }
      c.how += p.name;
      const size_t body = continues && r.Chance(0.85) ? 12 : r.Below(100);
      if (body < 12) {
        // Wholly random bytes, of any length up to a little past the largest seed.
        c.args.resize(r.Chance(0.1) ? r.Below(FF_MAX_BATCH * 48 + 64) : r.Below(256));
        for (unsigned char& b : c.args) b = static_cast<unsigned char>(r.U32());
        if (r.Chance(0.5) && c.args.size() >= 8) Set32(&c.args, 4, r.Pick(kCounts));
        c.how += " random body of " + std::to_string(c.args.size()) + " bytes";
      } else {
        const Seed s = p.make(r, context);
        REQUIRE(s.layout.size == s.bytes.size());  // the layout describes rpcgen's bytes
        c.args = s.bytes;
        if (body < 25) {
          c.how += " valid arguments";
        } else {
          for (size_t i = 0, n = 1 + r.Below(3); i < n; ++i)
            c.how += (i ? ", " : " damaged: ") + Mutate(r, s.layout, &c.args);
        }
      }
      if (r.Chance(0.03)) c.fragments = 2 + static_cast<int>(r.Below(3));
    }
    return calls;
  }

  CaseResult Run(uint64_t seed) {
    Rng r(seed);
    std::vector<Call> calls = MakeCalls(r);
    // Sometimes the client goes away without reading: the reply (a load's, held while it is
    // built, included) goes to a closed connection.
    const bool abandon = r.Chance(0.02);
    if (fd < 0 || r.Chance(0.02)) Reconnect();
    Bytes stream;
    std::vector<Expectation> expected;
    for (const Call& c : calls) {
      const Bytes rec = Record(r, c);
      expected.push_back(Expect(procs, c, rec.size() - 4 * static_cast<size_t>(c.fragments)));
      stream.insert(stream.end(), rec.begin(), rec.end());
    }
    if (trace)
      for (const Call& c : calls)
        std::fprintf(stderr, "case %llu: %s, %d fragment(s)\n",
                     static_cast<unsigned long long>(seed), c.how.c_str(), c.fragments);
    CaseResult result;
    const bool sent = SendAll(fd, stream);
    bool frays = false;
    for (const Expectation& e : expected) frays = frays || e.may_close;
    if (abandon) {
      if (trace)
        std::fprintf(stderr, "sent %zu call(s) and closed without reading\n", calls.size());
      Reconnect();
      return result;
    }
    for (size_t i = 0; i < calls.size(); ++i) {
      const Call& c = calls[i];
      const Expectation& e = expected[i];
      const std::string what = "call " + std::to_string(i + 1) + " of " +
                               std::to_string(calls.size()) + " (" + c.how + ", " +
                               std::to_string(c.fragments) + " fragment(s)): ";
      Bytes rec;
      const Got got = ReadRecord(fd, &rec);
      if (got == Got::kTimeout) {
        result.problem = what + "no reply within " + std::to_string(kReplyTimeoutS) + " s" +
                         (sent ? "" : " (the send did not complete)");
        return result;
      }
      if (got == Got::kBadFraming) {
        result.problem = what + "a reply record larger than any footfalld sends";
        return result;
      }
      if (trace && got == Got::kClosed) std::fprintf(stderr, "%sclosed\n", what.c_str());
      if (got == Got::kClosed) {
        // Allowed when a call of this case, or one before it on the connection, may close it:
        // libtirpc may answer a call sent in several fragments and then close the connection at
        // a later call, and a close with later calls unread resets the connection, which
        // discards replies still on their way.
        bool allowed = frayed;
        for (const Expectation& later : expected) allowed = allowed || later.may_close;
        if (!allowed) {
          result.problem =
              what + "the server closed the connection (expected " + Name(e.expect) + ")";
          return result;
        }
        ++closes;
        result.closed = true;
        Reconnect();
        return result;
      }
      Answer answer{};
      Bytes body;
      const std::string malformed = ParseReply(rec, c.xid, &answer, &body);
      if (trace)
        std::fprintf(stderr, "%s%s %s\n", what.c_str(), Name(answer),
                     answer == Answer::kSuccess && body.size() >= 4
                         ? ("status " + std::to_string(Get32(body.data()))).c_str()
                         : "");
      if (!malformed.empty()) {
        result.problem = what + "malformed reply: " + malformed + ": " + Hex(rec);
        return result;
      }
      ++answers[static_cast<int>(answer)];
      if (answer != e.expect && !(e.may_garble && answer == Answer::kGarbageArgs)) {
        result.problem = what + "answered " + Name(answer) + ", expected " + Name(e.expect);
        return result;
      }
      if (answer == Answer::kSuccess) {
        const std::string bad = procs[c.proc].check(c.args, body, &context);
        if (!bad.empty()) {
          result.problem = what + bad + "; reply body " + Hex(body);
          return result;
        }
        if (body.size() >= 4 && c.proc != FF_NULL && c.proc != FF_LIST) {
          const uint32_t status = Get32(body.data());
          if (status < 10) ++statuses[status];
        }
      }
    }
    frayed = frayed || frays;
    return result;
  }

  std::string Tally() const {
    std::string t;
    for (int a = 0; a < 8; ++a)
      if (answers[a])
        t += std::string(Name(static_cast<Answer>(a))) + " " + std::to_string(answers[a]) + ", ";
    t += "closed " + std::to_string(closes) + ", connections " + std::to_string(reconnects) +
         "; statuses:";
    for (int s = 0; s < 10; ++s) t += " " + std::to_string(statuses[s]);
    return t;
  }
};

}  // namespace

TEST_CASE("RPC fuzz: damaged and random calls to every procedure get well-formed replies",
          "[rpc][fuzz]") {
  DataRoot root;
  // footfalld's memory is measured: with glibc's mmap threshold fixed (it otherwise rises to the
  // largest block freed), freed record buffers and replies (a few hundred KiB each) go back to
  // the system at once rather than fragmenting the heap in steps of megabytes, so its resident
  // size follows what it holds. (The variable is read at footfalld's start, and only by it.)
  setenv("MALLOC_MMAP_THRESHOLD_", "65536", 1);
  ServerProcess server(0, FuzzServerArgs(root));
  unsetenv("MALLOC_MMAP_THRESHOLD_");
  RpcOptions o;
  o.port = server.port();
  o.call_timeout_s = 10;
  auto rpc = MakeRpcSession(o);
  auto embedded = MakeEmbeddedSession();
  const RawSamples terrain = FuzzTerrain();
  TerrainHandle remote = 0, local = 0;
  REQUIRE(rpc->LoadSamples(terrain, "fuzz", &remote) == Status::kOk);
  REQUIRE(embedded->LoadSamples(terrain, "fuzz", &local) == Status::kOk);

  const std::vector<Procedure> procs = Procedures();
  for (size_t i = 0; i < procs.size(); ++i) REQUIRE(procs[i].number == i);
  REQUIRE(procs.size() == FF_ASK_AGAIN + 1);  // every procedure of footfall.x
  Sweep sweep{procs, server.port(), {}};
  sweep.context.main_terrain = OnlyTerrain(server.port());

  const int cases = FuzzCases();
  const uint64_t base = FuzzSeed();
  // The first quarter warms the server up (allocator pools, load threads, the recent-query
  // ring, record buffers); its memory is measured from there.
  const int warm = std::max(1, cases / 4);
  long rss_warm = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < cases; ++i) {
    const uint64_t seed = base * 1000003u + static_cast<uint64_t>(i);
    const CaseResult result = sweep.Run(seed);
    INFO("case " << i << ", seed " << seed << " (FOOTFALL_FUZZ_SEED " << base << ")");
    INFO(result.problem);
    std::string log;
    if (!result.problem.empty()) {
      log = server.Log();
      log = log.substr(std::max<size_t>(log.size(), 4000) - 4000);
    }
    INFO("footfalld log (end):\n" << log);
    REQUIRE(result.problem.empty());
    if ((i + 1) % kHealthEvery == 0 || i + 1 == cases)
      RequireHealthy(server, *rpc, remote, *embedded, local, seed);
    if (i + 1 == warm) rss_warm = server.RssKiB();
    if (std::getenv("FOOTFALL_FUZZ_RSS") && (i + 1) % 1000 == 0)
      std::fprintf(stderr, "after %d cases: server RSS %ld KiB\n", i + 1, server.RssKiB());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const long rss_end = server.RssKiB();
  const std::string log = server.Log();
  if (sweep.trace) std::fprintf(stderr, "footfalld's log:\n%s", log.c_str());
  size_t in_parts = 0;
  for (size_t at = 0; (at = log.find("past its time limit", at)) != std::string::npos; ++at)
    ++in_parts;
  WARN(cases << " cases in " << seconds << " s: " << sweep.Tally() << "; batches answered in parts "
             << in_parts << "; server RSS " << rss_warm << " KiB after warm-up, " << rss_end
             << " KiB at the end");
  // What a case may leave behind is bounded and is there after the warm-up: tiny terrains and
  // uploads (freed a second after their connection closes or goes quiet), at most 20000 samples
  // in all (--max-samples), the ring of 4096 recent queries, a record buffer per open connection
  // (three at most here). With the mmap threshold fixed, the resident size then stays within
  // about 1 MiB over 40000 cases. A leak of 4 KiB per malformed call (a quarter of the calls)
  // would add some 9 MiB over the default sweep; of the 96 KiB a batch decodes, far more.
  INFO("server RSS after warm-up " << rss_warm << " KiB, at the end " << rss_end << " KiB");
  CHECK(rss_end - rss_warm < 3 * 1024);
  CHECK(rpc->Snap(remote, Vec3{5, 1, 5}).status == Status::kOk);
}

TEST_CASE("RPC fuzz: arguments cut short at any length are refused with GARBAGE_ARGS",
          "[rpc][fuzz]") {
  FuzzServer fuzz;
  const ServerProcess& server = fuzz.server;
  TerrainSession* rpc = fuzz.rpc.get();
  const TerrainHandle remote = fuzz.remote;
  Context context;
  context.main_terrain = OnlyTerrain(server.port());
  RawConnection raw(server.port());
  size_t calls = 0;
  for (const Procedure& p : Procedures()) {
    if (!p.args_xdr) continue;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      Rng r(seed);
      const Seed s = p.make(r, context);
      // Cut at every byte of a short request; of a long one (a batch, a chunk) at every byte of
      // its first and last 256 and every 4 KiB between. The connection stays open throughout.
      const size_t size = s.bytes.size();
      auto next = [&](size_t cut) {
        const bool between = cut >= 256 && cut + 256 < size;
        return between ? std::min(size - 256, cut + 4096 - cut % 4096 + seed % 4) : cut + 1;
      };
      for (size_t cut = 0; cut < size; cut = next(cut)) {
        const Bytes args(s.bytes.begin(), s.bytes.begin() + static_cast<ptrdiff_t>(cut));
        INFO(p.name << " seed " << seed << " cut to " << cut << " of " << s.bytes.size()
                    << " bytes: " << Hex(args));
        REQUIRE_FALSE(ArgsDecode(p, args));
        Answer answer{};
        Bytes body;
        REQUIRE(raw.Call(p.number, args, &answer, &body));
        CHECK(Name(answer) == std::string(Name(Answer::kGarbageArgs)));
        ++calls;
      }
    }
  }
  INFO(calls << " calls");
  CHECK(calls > 500);
  CHECK(rpc->Snap(remote, Vec3{5, 1, 5}).status == Status::kOk);
}

TEST_CASE("RPC fuzz: array and string lengths past their bounds are refused and cost no memory",
          "[rpc][fuzz]") {
  DataRoot root;
  setenv("MALLOC_MMAP_THRESHOLD_", "65536", 1);  // as in the sweep: RSS follows what is held
  ServerProcess server(0, FuzzServerArgs(root));
  unsetenv("MALLOC_MMAP_THRESHOLD_");
  Context context;
  context.main_terrain = 1;
  const std::vector<Procedure> procs = Procedures();
  // Every length field of every procedure, replaced with every count past its bound (and the
  // rest of the request as sent: a full batch claims 65536 items, a short one 4 billion).
  auto round = [&](RawConnection& raw) {
    size_t calls = 0;
    for (const Procedure& p : procs) {
      Rng r(7);
      Seed s = p.make(r, context);
      for (const auto& [at, kind] : s.layout.fields) {
        if (kind != Field::kCount) continue;
        for (const uint32_t count : kCounts) {
          Bytes args = s.bytes;
          Set32(&args, at, count);
          if (ArgsDecode(p, args)) continue;  // a string of 257 bytes may be within its bound
          INFO(p.name << ": length at " << at << " := " << count);
          Answer answer{};
          Bytes body;
          REQUIRE(raw.Call(p.number, args, &answer, &body));
          CHECK(Name(answer) == std::string(Name(Answer::kGarbageArgs)));
          ++calls;
        }
      }
    }
    return calls;
  };
  {
    RawConnection raw(server.port());
    REQUIRE(round(raw) > 30);
  }
  const long before = server.RssKiB();
  for (int i = 0; i < 40; ++i) {
    RawConnection raw(server.port());
    round(raw);
  }
  const long after = server.RssKiB();
  INFO("server RSS " << before << " KiB before 40 rounds, " << after << " KiB after");
  CHECK(after - before < 2048);
}

TEST_CASE("RPC fuzz: a non-finite double in any query or load field answers FF_INVALID_ARGUMENT",
          "[rpc][fuzz]") {
  FuzzServer fuzz;
  const ServerProcess& server = fuzz.server;
  TerrainSession* rpc = fuzz.rpc.get();
  const TerrainHandle remote = fuzz.remote;
  const uint32_t terrain = OnlyTerrain(server.port());
  const double bad[] = {
      std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
      std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  auto with = [](Bytes args, size_t at, double d) {
    uint64_t bits;
    std::memcpy(&bits, &d, 8);
    Set64(&args, at, bits);
    return args;
  };
  RawConnection raw(server.port());
  size_t checked = 0;
  SECTION("queries") {
    // Fixed, valid queries on the terrain: every double of each replaced in turn.
    ff_point_args point{terrain, {5, 1, 5}};
    const Bytes point_args = Encode(FF_XDR(ff_point_args), &point);
    ff_next_args next{terrain, 0.2, {{5, 1, 5}, {0.5, 0, 0}}};
    const Bytes next_args = Encode(FF_XDR(ff_next_args), &next);
    for (const double d : bad) {
      for (const uint32_t proc : {FF_SNAP, FF_NORMAL})
        for (size_t at = 4; at < 28; at += 8) {
          INFO("proc " << proc << " double at " << at << " := " << d);
          CHECK(raw.Status(proc, with(point_args, at, d)) == FF_INVALID_ARGUMENT);
          ++checked;
        }
      for (size_t at = 4; at < 60; at += 8) {
        INFO("FF_NEXT double at " << at << " := " << d);
        CHECK(raw.Status(FF_NEXT, with(next_args, at, d)) == FF_INVALID_ARGUMENT);
        ++checked;
      }
    }
    // Batches: three queries, the middle one damaged; the others are answered.
    std::vector<ff_vec3> points = {{5, 1, 5}, {4, 1, 4}, {6, 1, 6}};
    ff_point_batch_args pb{};
    pb.terrain = terrain;
    pb.points.points_len = 3;
    pb.points.points_val = points.data();
    const Bytes pb_args = Encode(FF_XDR(ff_point_batch_args), &pb);
    std::vector<ff_next_query> steps(3, ff_next_query{{5, 1, 5}, {0.5, 0, 0}});
    ff_next_batch_args nb{};
    nb.terrain = terrain;
    nb.tolerance = 0.2;
    nb.queries.queries_len = 3;
    nb.queries.queries_val = steps.data();
    const Bytes nb_args = Encode(FF_XDR(ff_next_batch_args), &nb);
    // The statuses of a batch; asked again while a query is past the (very short) batch time
    // limit, as clients do.
    auto batch = [&](uint32_t proc, const Bytes& args) {
      std::vector<int> statuses;
      for (int call = 0; call < 100; ++call) {
        Answer answer{};
        Bytes body;
        REQUIRE(raw.Call(proc, args, &answer, &body));
        REQUIRE(answer == Answer::kSuccess);
        ff_batch_reply reply;
        REQUIRE(DecodeWhole(FF_XDR(ff_batch_reply), body, &reply) == "");
        statuses = {reply.status};
        for (u_int i = 0; i < reply.results.results_len; ++i)
          statuses.push_back(reply.results.results_val[i].status);
        Free(FF_XDR(ff_batch_reply), &reply);
        if (std::find(statuses.begin(), statuses.end(), FF_LIMIT_EXCEEDED) == statuses.end()) break;
      }
      return statuses;
    };
    const std::vector<int> middle_invalid = {FF_OK, FF_OK, FF_INVALID_ARGUMENT, FF_OK};
    for (const double d : bad) {
      for (const uint32_t proc : {FF_SNAP_BATCH, FF_NORMAL_BATCH})
        for (size_t at = 8 + 24; at < 8 + 48; at += 8) {
          INFO("proc " << proc << " double at " << at << " := " << d);
          CHECK(batch(proc, with(pb_args, at, d)) == middle_invalid);
          ++checked;
        }
      for (size_t at = 16 + 48; at < 16 + 96; at += 8) {
        INFO("FF_NEXT_BATCH double at " << at << " := " << d);
        CHECK(batch(FF_NEXT_BATCH, with(nb_args, at, d)) == middle_invalid);
        ++checked;
      }
      INFO("FF_NEXT_BATCH tolerance := " << d);
      CHECK(batch(FF_NEXT_BATCH, with(nb_args, 4, d)) == std::vector<int>{FF_INVALID_ARGUMENT});
      ++checked;
    }
    CHECK(checked == 4 * (2 * 3 + 7 + 2 * 3 + 6 + 1));
  }
  SECTION("loads and uploads") {
    ff_load_args load{const_cast<char*>("corner.obj"), 0.5};
    const Bytes load_args = Encode(FF_XDR(ff_load_args), &load);
    ff_load_options_args options{};
    options.path = const_cast<char*>("corner.obj");
    options.separation = 0.5;
    options.smooth_normals = 1;
    options.crease_angle_deg = 30;
    options.up_axis = 'y';
    options.height_scale = 1;
    options.max_samples = 10000;
    const Bytes options_args = Encode(FF_XDR(ff_load_options_args), &options);
    REQUIRE(raw.Status(FF_LOAD, load_args) == FF_OK);
    REQUIRE(raw.Status(FF_LOAD_OPTIONS, options_args) == FF_OK);
    // Offsets after the path (4 + 12 bytes): separation; then finest_default, smooth_normals,
    // crease_angle_deg, seed, up_axis, cell_size, height_scale.
    const size_t option_doubles[] = {16, 24, 36, 56, 64};
    for (const double d : bad) {
      INFO("FF_LOAD separation := " << d);
      CHECK(raw.Status(FF_LOAD, with(load_args, 16, d)) == FF_INVALID_ARGUMENT);
      ++checked;
      for (const size_t at : option_doubles) {
        INFO("FF_LOAD_OPTIONS double at " << at << " := " << d);
        CHECK(raw.Status(FF_LOAD_OPTIONS, with(options_args, at, d)) == FF_INVALID_ARGUMENT);
        ++checked;
      }
      for (size_t at = 8; at < 8 + 48; at += 8) {
        // A new upload of one sample on a new connection for each (four at most per connection).
        RawConnection uploader(server.port());
        std::string name = "nan";
        ff_upload_begin_args begin{name.data(), 1};
        Answer answer{};
        Bytes body;
        REQUIRE(uploader.Call(FF_UPLOAD_BEGIN, Encode(FF_XDR(ff_upload_begin_args), &begin),
                              &answer, &body));
        ff_upload_reply reply;
        REQUIRE(DecodeWhole(FF_XDR(ff_upload_reply), body, &reply) == "");
        REQUIRE(reply.status == FF_OK);
        ff_sample sample{{1, 0, 1}, {0, 1, 0}};
        ff_upload_chunk_args chunk{};
        chunk.upload = reply.upload;
        chunk.samples.samples_len = 1;
        chunk.samples.samples_val = &sample;
        Free(FF_XDR(ff_upload_reply), &reply);
        INFO("FF_UPLOAD_CHUNK double at " << at << " := " << d);
        CHECK(uploader.Status(FF_UPLOAD_CHUNK, with(Encode(FF_XDR(ff_upload_chunk_args), &chunk),
                                                    at, d)) == FF_INVALID_ARGUMENT);
        ++checked;
      }
    }
    CHECK(checked == 4 * (1 + 5 + 6));
  }
  CHECK(rpc->Snap(remote, Vec3{5, 1, 5}).status == Status::kOk);
}

TEST_CASE("RPC fuzz: a call in several fragments is dropped or answered and others are served",
          "[rpc][fuzz]") {
  // footfall.x asks clients to keep each request in one fragment: libtirpc's non-blocking server
  // drops one in several. Here, what dropping means: GARBAGE_ARGS or a closed connection (at
  // once or at a later call), never a wrong SUCCESS, a hang or harm to other clients.
  FuzzServer fuzz;
  const ServerProcess& server = fuzz.server;
  TerrainSession* rpc = fuzz.rpc.get();
  const TerrainHandle remote = fuzz.remote;
  const uint32_t terrain = OnlyTerrain(server.port());
  ff_point_args point{terrain, {5, 1, 5}};
  const Bytes args = Encode(FF_XDR(ff_point_args), &point);
  size_t answered = 0, garbage = 0, closed = 0;
  for (int fragments = 2; fragments <= 6; ++fragments) {
    for (int i = 0; i < 20; ++i) {
      RawConnection raw(server.port());
      raw.xid = static_cast<uint32_t>(100 * fragments + i);
      for (int call = 0; call < 3; ++call) {
        Answer answer{};
        Bytes body;
        INFO(fragments << " fragments, try " << i << ", call " << call);
        if (!raw.Call(FF_SNAP, args, &answer, &body, call == 0 ? fragments : 1)) {
          ++closed;
          break;
        }
        if (answer == Answer::kGarbageArgs) {
          ++garbage;
          continue;
        }
        REQUIRE(answer == Answer::kSuccess);
        ff_result result;
        REQUIRE(DecodeWhole(FF_XDR(ff_result), body, &result) == "");
        CHECK(result.status == FF_OK);
        ++answered;
      }
    }
  }
  WARN("calls after one in several fragments: " << answered << " answered, " << garbage
                                                << " GARBAGE_ARGS, " << closed
                                                << " connections closed");
  CHECK(rpc->Snap(remote, Vec3{5, 1, 5}).status == Status::kOk);
}
