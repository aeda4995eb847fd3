// The fast batch filters (rpc/include/footfall/rpc/batch_xdr.h) against rpcgen's: the same bytes
// for the same values, in aligned and unaligned memory buffers (inline and element-wise paths)
// and in record streams with small buffers (inline chunks cut at fragment boundaries); the same
// values decoded back; clean failures on short buffers and on arrays claiming more items than
// they carry, without leaks.
#include <malloc.h>
#include <rpc/rpc.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall.h"
#include "footfall/rpc/batch_xdr.h"
#include "footfall/terrain/grid.h"

using namespace footfall;

namespace {

template <typename T>
using Filter = bool_t (*)(XDR*, T*);

// Any bit pattern: NaNs with payloads, infinities, denormals, negative zero.
double AnyDouble(std::mt19937_64& rng) {
  const uint64_t bits = rng();
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

template <typename Vec>
void Fill(std::mt19937_64& rng, Vec* v) {
  v->x = AnyDouble(rng), v->y = AnyDouble(rng), v->z = AnyDouble(rng);
}

// An enum field set to any 4-byte value, also outside the enumeration.
template <typename E>
void AnyEnum(std::mt19937_64& rng, E* e) {
  const int32_t v = rng() % 3 ? static_cast<int32_t>(rng() % 10) : static_cast<int32_t>(rng());
  std::memcpy(e, &v, 4);
}

// The encoded bytes and whether the filter succeeded, in a buffer `misalign` bytes off an
// 8-byte boundary (libtirpc has no inline space in unaligned memory buffers).
struct Encoded {
  bool ok = false;
  std::vector<char> bytes;
};

template <typename T>
Encoded Encode(Filter<T> filter, T* value, size_t capacity, size_t misalign = 0) {
  std::vector<char> storage(capacity + 16);
  char* buf = storage.data() + 8 + misalign;
  XDR x;
  xdrmem_create(&x, buf, static_cast<u_int>(capacity), XDR_ENCODE);
  Encoded e;
  e.ok = filter(&x, value) != FALSE;
  e.bytes.assign(buf, buf + xdr_getpos(&x));
  XDR_DESTROY(&x);
  return e;
}

template <typename T>
bool Decode(Filter<T> filter, const std::vector<char>& bytes, T* value, size_t misalign = 0) {
  std::vector<char> storage(bytes.size() + 16);
  char* buf = storage.data() + 8 + misalign;
  if (!bytes.empty()) std::memcpy(buf, bytes.data(), bytes.size());
  XDR x;
  xdrmem_create(&x, buf, static_cast<u_int>(bytes.size()), XDR_DECODE);
  const bool ok = filter(&x, value) != FALSE;
  XDR_DESTROY(&x);
  return ok;
}

template <typename T>
void Free(Filter<T> filter, T* value) {
  xdr_free(reinterpret_cast<xdrproc_t>(filter), reinterpret_cast<char*>(value));
}

template <typename A, typename B>
bool SameBits(const A& a, const B& b) {
  static_assert(sizeof(A) == sizeof(B), "same layout");
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Statuses are compared as the 32-bit values the tests put there, any value: loading one outside
// ff_status's range as the enum is undefined behaviour.
bool SameResult(const ff_result& a, const ff_result& b) {
  return SameBits(a.status, b.status) && a.index == b.index && SameBits(a.point, b.point) &&
         SameBits(a.normal, b.normal);
}
template <typename Result>
bool SameResult(const ff_result& a, const Result& b) {
  return SameBits(a.status, b.status) && a.index == b.index && SameBits(a.point, b.point) &&
         SameBits(a.normal, b.normal);
}

// Test values, owning their arrays.
struct PointBatch {
  std::vector<ff_vec3> points;
  ff_point_batch_args args{};
  PointBatch(std::mt19937_64& rng, size_t n) : points(n) {
    for (auto& p : points) Fill(rng, &p);
    args.terrain = static_cast<u_int>(rng());
    args.points.points_len = static_cast<u_int>(n);
    args.points.points_val = points.data();
  }
};

struct NextBatch {
  std::vector<ff_next_query> queries;
  ff_next_batch_args args{};
  NextBatch(std::mt19937_64& rng, size_t n) : queries(n) {
    for (auto& q : queries) Fill(rng, &q.foot), Fill(rng, &q.direction);
    args.terrain = static_cast<u_int>(rng());
    args.tolerance = AnyDouble(rng);
    args.queries.queries_len = static_cast<u_int>(n);
    args.queries.queries_val = queries.data();
  }
};

struct BatchReply {
  std::vector<ff_result> results;
  ff_batch_reply reply{};
  BatchReply(std::mt19937_64& rng, size_t n) : results(n) {
    for (auto& r : results) {
      AnyEnum(rng, &r.status);
      r.index = static_cast<u_int>(rng());
      Fill(rng, &r.point), Fill(rng, &r.normal);
    }
    AnyEnum(rng, &reply.status);
    reply.results.results_len = static_cast<u_int>(n);
    reply.results.results_val = results.data();
  }
};

const size_t kCounts[] = {0, 1, 2, 63, 64, 65, 1000, FF_MAX_BATCH};
constexpr size_t kBig = 1 << 20;  // bytes: room for any batch

// Record streams in memory, with small buffers so that records span several fragments.
struct Pipe {
  std::string data;
  size_t read = 0;
  size_t reads = 0;
  static int Write(void* self, void* buf, int len) {
    static_cast<Pipe*>(self)->data.append(static_cast<char*>(buf), static_cast<size_t>(len));
    return len;
  }
  static int Read(void* self, void* buf, int len) {
    Pipe* p = static_cast<Pipe*>(self);
    // Reads of varying length, as a socket gives: the buffer's room, or only 1000 or 37 bytes.
    const size_t cap[] = {static_cast<size_t>(len), 1000, 37};
    const size_t n = std::min({cap[p->reads++ % 3], p->data.size() - p->read});
    if (n == 0) return -1;
    std::memcpy(buf, p->data.data() + p->read, n);
    p->read += n;
    return static_cast<int>(n);
  }
};

template <typename T>
std::string EncodeRecord(Filter<T> filter, T* value, u_int buffer) {
  Pipe pipe;
  XDR x;
  xdrrec_create(&x, buffer, buffer, &pipe, Pipe::Read, Pipe::Write);
  x.x_op = XDR_ENCODE;
  REQUIRE(filter(&x, value));
  REQUIRE(xdrrec_endofrecord(&x, TRUE));
  XDR_DESTROY(&x);
  return pipe.data;
}

template <typename T>
bool DecodeRecord(Filter<T> filter, const std::string& record, u_int buffer, T* value) {
  Pipe pipe;
  pipe.data = record;
  XDR x;
  xdrrec_create(&x, buffer, buffer, &pipe, Pipe::Read, Pipe::Write);
  x.x_op = XDR_DECODE;
  xdrrec_skiprecord(&x);
  const bool ok = filter(&x, value) != FALSE;
  XDR_DESTROY(&x);
  return ok;
}

size_t HeapInUse() { return mallinfo2().uordblks; }

}  // namespace

TEST_CASE("fast batch filters put the bytes rpcgen puts", "[rpc][xdr]") {
  std::mt19937_64 rng(11);
  for (const size_t n : kCounts) {
    for (const size_t misalign : {size_t{0}, size_t{1}, size_t{4}}) {
      INFO(n << " items, buffer " << misalign << " bytes off alignment");
      {
        PointBatch b(rng, n);
        const Encoded slow = Encode(xdr_ff_point_batch_args, &b.args, kBig, misalign);
        const Encoded fast = Encode(FastXdrPointBatchArgs, &b.args, kBig, misalign);
        REQUIRE(slow.ok);
        REQUIRE(fast.ok);
        REQUIRE(fast.bytes == slow.bytes);
        // The view over the engine's own Vec3.
        std::vector<Vec3> points(n);
        for (size_t i = 0; i < n; ++i) points[i] = {b.points[i].x, b.points[i].y, b.points[i].z};
        PointBatchView<Vec3> view;
        view.terrain = b.args.terrain;
        view.count = view.capacity = static_cast<u_int>(n);
        view.points = points.data();
        const Encoded v = Encode(XdrPointBatchView<Vec3>, &view, kBig, misalign);
        REQUIRE(v.ok);
        REQUIRE(v.bytes == slow.bytes);
      }
      {
        NextBatch b(rng, n);
        const Encoded slow = Encode(xdr_ff_next_batch_args, &b.args, kBig, misalign);
        const Encoded fast = Encode(FastXdrNextBatchArgs, &b.args, kBig, misalign);
        REQUIRE(slow.ok);
        REQUIRE(fast.ok);
        REQUIRE(fast.bytes == slow.bytes);
        std::vector<StepQuery> steps(n);
        for (size_t i = 0; i < n; ++i) {
          const ff_next_query& q = b.queries[i];
          steps[i] = {{q.foot.x, q.foot.y, q.foot.z},
                      {q.direction.x, q.direction.y, q.direction.z}};
        }
        NextBatchView<StepQuery> view;
        view.terrain = b.args.terrain;
        view.tolerance = b.args.tolerance;
        view.count = view.capacity = static_cast<u_int>(n);
        view.queries = steps.data();
        const Encoded v = Encode(XdrNextBatchView<StepQuery>, &view, kBig, misalign);
        REQUIRE(v.ok);
        REQUIRE(v.bytes == slow.bytes);
      }
      {
        BatchReply b(rng, n);
        const Encoded slow = Encode(xdr_ff_batch_reply, &b.reply, kBig, misalign);
        const Encoded fast = Encode(FastXdrBatchReply, &b.reply, kBig, misalign);
        REQUIRE(slow.ok);
        REQUIRE(fast.ok);
        REQUIRE(fast.bytes == slow.bytes);
        // The view over the engine's Foothold, whose status is a footfall::Status.
        std::vector<Foothold> results(n);
        for (size_t i = 0; i < n; ++i) {
          std::memcpy(&results[i].status, &b.results[i].status, 4);
          results[i].index = b.results[i].index;
          const ff_vec3 &p = b.results[i].point, &m = b.results[i].normal;
          results[i].point = {p.x, p.y, p.z};
          results[i].normal = {m.x, m.y, m.z};
        }
        BatchReplyView<Foothold> view;
        std::memcpy(&view.status, &b.reply.status, sizeof view.status);  // any 32-bit value
        view.count = view.capacity = static_cast<u_int>(n);
        view.results = results.data();
        const Encoded v = Encode(XdrBatchReplyView<Foothold>, &view, kBig, misalign);
        REQUIRE(v.ok);
        REQUIRE(v.bytes == slow.bytes);
      }
    }
  }
}

TEST_CASE("fast batch filters decode what rpcgen encoded", "[rpc][xdr]") {
  std::mt19937_64 rng(12);
  for (const size_t n : kCounts) {
    for (const size_t misalign : {size_t{0}, size_t{1}}) {
      INFO(n << " items, buffer " << misalign << " bytes off alignment");
      {
        PointBatch b(rng, n);
        const Encoded wire = Encode(xdr_ff_point_batch_args, &b.args, kBig);
        ff_point_batch_args fast{};
        REQUIRE(Decode(FastXdrPointBatchArgs, wire.bytes, &fast, misalign));
        REQUIRE(fast.terrain == b.args.terrain);
        REQUIRE(fast.points.points_len == n);
        for (size_t i = 0; i < n; ++i) REQUIRE(SameBits(fast.points.points_val[i], b.points[i]));
        Free(xdr_ff_point_batch_args, &fast);  // rpcgen frees what the fast filter allocated
        REQUIRE(fast.points.points_val == nullptr);

        ff_point_batch_args slow{};
        REQUIRE(Decode(xdr_ff_point_batch_args, wire.bytes, &slow, misalign));
        Free(FastXdrPointBatchArgs, &slow);  // and the other way round
        REQUIRE(slow.points.points_val == nullptr);

        std::vector<Vec3> points(FF_MAX_BATCH);
        PointBatchView<Vec3> view;
        view.points = points.data();
        view.capacity = FF_MAX_BATCH;
        REQUIRE(Decode(XdrPointBatchView<Vec3>, wire.bytes, &view, misalign));
        REQUIRE(view.terrain == b.args.terrain);
        REQUIRE(view.count == n);
        for (size_t i = 0; i < n; ++i) REQUIRE(SameBits(points[i], b.points[i]));
      }
      {
        NextBatch b(rng, n);
        const Encoded wire = Encode(xdr_ff_next_batch_args, &b.args, kBig);
        ff_next_batch_args fast{};
        REQUIRE(Decode(FastXdrNextBatchArgs, wire.bytes, &fast, misalign));
        REQUIRE(fast.terrain == b.args.terrain);
        REQUIRE(SameBits(fast.tolerance, b.args.tolerance));
        REQUIRE(fast.queries.queries_len == n);
        for (size_t i = 0; i < n; ++i) REQUIRE(SameBits(fast.queries.queries_val[i], b.queries[i]));
        Free(xdr_ff_next_batch_args, &fast);

        std::vector<StepQuery> steps(FF_MAX_BATCH);
        NextBatchView<StepQuery> view;
        view.queries = steps.data();
        view.capacity = FF_MAX_BATCH;
        REQUIRE(Decode(XdrNextBatchView<StepQuery>, wire.bytes, &view, misalign));
        REQUIRE(view.count == n);
        REQUIRE(SameBits(view.tolerance, b.args.tolerance));
        for (size_t i = 0; i < n; ++i) REQUIRE(SameBits(steps[i], b.queries[i]));
      }
      {
        BatchReply b(rng, n);
        const Encoded wire = Encode(xdr_ff_batch_reply, &b.reply, kBig);
        ff_batch_reply fast{};
        REQUIRE(Decode(FastXdrBatchReply, wire.bytes, &fast, misalign));
        REQUIRE(SameBits(fast.status, b.reply.status));
        REQUIRE(fast.results.results_len == n);
        for (size_t i = 0; i < n; ++i)
          REQUIRE(SameResult(b.results[i], fast.results.results_val[i]));
        Free(xdr_ff_batch_reply, &fast);

        std::vector<Foothold> results(FF_MAX_BATCH);
        BatchReplyView<Foothold> view;
        view.results = results.data();
        view.capacity = FF_MAX_BATCH;
        REQUIRE(Decode(XdrBatchReplyView<Foothold>, wire.bytes, &view, misalign));
        REQUIRE(SameBits(view.status, b.reply.status));
        REQUIRE(view.count == n);
        for (size_t i = 0; i < n; ++i) REQUIRE(SameResult(b.results[i], results[i]));
      }
    }
  }
}

TEST_CASE("fast batch filters in record streams cut into fragments", "[rpc][xdr]") {
  std::mt19937_64 rng(13);
  // Buffers of 4000 bytes: a full batch spans many fragments, and inline chunks of up to 64
  // items (3.5 KiB of results) meet fragment and read boundaries at every offset.
  for (const u_int buffer : {4000u, 262144u}) {
    for (const size_t n : {size_t{65}, size_t{1000}, size_t{FF_MAX_BATCH}}) {
      INFO(n << " items, record buffers of " << buffer << " bytes");
      BatchReply b(rng, n);
      const std::string slow = EncodeRecord(xdr_ff_batch_reply, &b.reply, buffer);
      REQUIRE(EncodeRecord(FastXdrBatchReply, &b.reply, buffer) == slow);
      std::vector<Foothold> results(FF_MAX_BATCH);
      BatchReplyView<Foothold> view;
      view.results = results.data();
      view.capacity = FF_MAX_BATCH;
      REQUIRE(DecodeRecord(XdrBatchReplyView<Foothold>, slow, buffer, &view));
      REQUIRE(view.count == n);
      for (size_t i = 0; i < n; ++i) REQUIRE(SameResult(b.results[i], results[i]));

      PointBatch p(rng, n);
      const std::string points = EncodeRecord(xdr_ff_point_batch_args, &p.args, buffer);
      REQUIRE(EncodeRecord(FastXdrPointBatchArgs, &p.args, buffer) == points);
      ff_point_batch_args fast{};
      REQUIRE(DecodeRecord(FastXdrPointBatchArgs, points, buffer, &fast));
      REQUIRE(fast.points.points_len == n);
      for (size_t i = 0; i < n; ++i) REQUIRE(SameBits(fast.points.points_val[i], p.points[i]));
      Free(FastXdrPointBatchArgs, &fast);

      NextBatch q(rng, n);
      const std::string steps = EncodeRecord(xdr_ff_next_batch_args, &q.args, buffer);
      REQUIRE(EncodeRecord(FastXdrNextBatchArgs, &q.args, buffer) == steps);
    }
  }
}

TEST_CASE("fast batch filters fail cleanly on short and lying input", "[rpc][xdr][robustness]") {
  std::mt19937_64 rng(14);
  PointBatch points(rng, 100);
  NextBatch steps(rng, 100);
  BatchReply results(rng, 100);
  const std::vector<char> point_wire = Encode(xdr_ff_point_batch_args, &points.args, kBig).bytes;
  const std::vector<char> step_wire = Encode(xdr_ff_next_batch_args, &steps.args, kBig).bytes;
  const std::vector<char> result_wire = Encode(xdr_ff_batch_reply, &results.reply, kBig).bytes;
  std::vector<Vec3> vec_store(FF_MAX_BATCH);
  std::vector<StepQuery> step_store(FF_MAX_BATCH);
  std::vector<Foothold> result_store(FF_MAX_BATCH);

  // Every truncation of each message fails, in aligned and unaligned buffers, and what the
  // drop-in filters allocated before failing is freed by XDR_FREE. Returns how many decodes
  // wrongly succeeded (no assertions inside, so that heap use can be measured around it).
  auto truncations = [&](size_t misalign) {
    int wrong = 0;
    for (size_t len = 0; len < point_wire.size(); len += len < 64 ? 1 : 37) {
      const std::vector<char> cut(point_wire.begin(), point_wire.begin() + len);
      ff_point_batch_args a{};
      wrong += Decode(FastXdrPointBatchArgs, cut, &a, misalign);
      Free(FastXdrPointBatchArgs, &a);
      PointBatchView<Vec3> v;
      v.points = vec_store.data(), v.capacity = FF_MAX_BATCH;
      wrong += Decode(XdrPointBatchView<Vec3>, cut, &v, misalign);
    }
    for (size_t len = 0; len < step_wire.size(); len += len < 64 ? 1 : 41) {
      const std::vector<char> cut(step_wire.begin(), step_wire.begin() + len);
      ff_next_batch_args a{};
      wrong += Decode(FastXdrNextBatchArgs, cut, &a, misalign);
      Free(FastXdrNextBatchArgs, &a);
      NextBatchView<StepQuery> v;
      v.queries = step_store.data(), v.capacity = FF_MAX_BATCH;
      wrong += Decode(XdrNextBatchView<StepQuery>, cut, &v, misalign);
    }
    for (size_t len = 0; len < result_wire.size(); len += len < 64 ? 1 : 43) {
      const std::vector<char> cut(result_wire.begin(), result_wire.begin() + len);
      ff_batch_reply a{};
      wrong += Decode(FastXdrBatchReply, cut, &a, misalign);
      Free(FastXdrBatchReply, &a);
      BatchReplyView<Foothold> v;
      v.results = result_store.data(), v.capacity = FF_MAX_BATCH;
      wrong += Decode(XdrBatchReplyView<Foothold>, cut, &v, misalign);
    }
    return wrong;
  };

  SECTION("truncated messages") {
    CHECK(truncations(0) == 0);
    CHECK(truncations(1) == 0);
  }

  SECTION("truncated messages leak nothing") {
    truncations(0), truncations(1);  // warm up the allocator
    const size_t before = HeapInUse();
    int wrong = 0;
    for (int round = 0; round < 5; ++round) wrong += truncations(round % 2);
    const size_t after = HeapInUse();
    CHECK(wrong == 0);
    // Each round makes about 250 decodes that allocate an array (2.4 to 5.6 KB) before they
    // fail: a leak would add over 500 KB per round. A few hundred bytes of one-time
    // allocations (seen under ctest only) are tolerated.
    INFO("heap in use before " << before << " bytes, after " << after);
    CHECK(after <= before + 4096);
  }

  SECTION("an array claiming more items than it carries") {
    std::vector<char> lying = point_wire;
    const uint32_t claim = htonl(FF_MAX_BATCH);
    std::memcpy(lying.data() + 4, &claim, 4);  // 4096 claimed, 100 carried
    int wrong = 0;
    const size_t before = HeapInUse();
    for (int round = 0; round < 50; ++round) {
      ff_point_batch_args a{};
      wrong += Decode(FastXdrPointBatchArgs, lying, &a);  // allocates 4096 points, then fails
      Free(FastXdrPointBatchArgs, &a);
      wrong += a.points.points_val != nullptr;
      PointBatchView<Vec3> v;
      v.points = vec_store.data(), v.capacity = FF_MAX_BATCH;
      wrong += Decode(XdrPointBatchView<Vec3>, lying, &v);
    }
    const size_t after = HeapInUse();
    CHECK(wrong == 0);
    INFO("heap in use before " << before << " bytes, after " << after);
    CHECK(after <= before + 4096);  // a leak would add 50 x 96 KB

    std::vector<char> lying_steps = step_wire;
    std::memcpy(lying_steps.data() + 12, &claim, 4);  // after terrain and tolerance
    ff_next_batch_args s{};
    CHECK_FALSE(Decode(FastXdrNextBatchArgs, lying_steps, &s));
    Free(FastXdrNextBatchArgs, &s);

    std::vector<char> lying_results = result_wire;
    std::memcpy(lying_results.data() + 4, &claim, 4);
    BatchReplyView<Foothold> r;
    r.results = result_store.data(), r.capacity = FF_MAX_BATCH;
    CHECK_FALSE(Decode(XdrBatchReplyView<Foothold>, lying_results, &r));
  }

  SECTION("counts above the bound or the view's capacity are refused before any item") {
    std::vector<char> huge = point_wire;
    const uint32_t over = htonl(FF_MAX_BATCH + 1);
    std::memcpy(huge.data() + 4, &over, 4);
    ff_point_batch_args a{};
    CHECK_FALSE(Decode(FastXdrPointBatchArgs, huge, &a));
    CHECK(a.points.points_val == nullptr);  // nothing allocated

    PointBatchView<Vec3> v;
    v.points = vec_store.data(), v.capacity = 50;  // the message carries 100
    vec_store[50] = Vec3{7, 7, 7};
    CHECK_FALSE(Decode(XdrPointBatchView<Vec3>, point_wire, &v));
    CHECK(v.count == 0);
    CHECK(vec_store[50] == Vec3{7, 7, 7});  // nothing written past the capacity

    BatchReplyView<Foothold> none;  // no array at all
    CHECK_FALSE(Decode(XdrBatchReplyView<Foothold>, result_wire, &none));
  }

  SECTION("encoding into a buffer too small fails") {
    for (const size_t cap : {size_t{0}, size_t{7}, point_wire.size() - 4}) {
      CHECK_FALSE(Encode(FastXdrPointBatchArgs, &points.args, cap).ok);
      CHECK_FALSE(Encode(FastXdrPointBatchArgs, &points.args, cap, 1).ok);
    }
    CHECK_FALSE(Encode(FastXdrBatchReply, &results.reply, result_wire.size() - 1).ok);
    PointBatchView<Vec3> v;
    v.count = 100, v.capacity = 100, v.points = vec_store.data();
    CHECK_FALSE(Encode(XdrPointBatchView<Vec3>, &v, point_wire.size() - 8).ok);
  }
}
