// Fast XDR filters for the batch procedures of footfall.x (FF_SNAP_BATCH, FF_NORMAL_BATCH,
// FF_NEXT_BATCH and their ff_batch_reply).
//
// Every filter here puts and gets exactly the bytes of the rpcgen routine for the same .x type;
// only the speed differs. Runs of items are byte-swapped straight from or into the XDR stream's
// own buffer (XDR_INLINE), a chunk of items at a time; where the stream has no inline space (a
// full record buffer, a fragment boundary, an unaligned memory buffer) the filter falls back to
// the element-wise xdr_double / xdr_u_int for one item and tries inline again after it.
//
// Two kinds of in-memory forms:
// - FastXdrPointBatchArgs, FastXdrNextBatchArgs, FastXdrBatchReply: drop-in replacements for
//   xdr_ff_point_batch_args, xdr_ff_next_batch_args, xdr_ff_batch_reply, with the same memory
//   contract (decode allocates the array when its pointer is NULL, XDR_FREE frees it, with
//   calloc/free as libtirpc does), so either routine may free what the other decoded.
// - the views (PointBatchView, NextBatchView, BatchReplyView): the items live in a caller-owned
//   array of `capacity` items of any type with the .x field names (ff_vec3 or footfall::Vec3 for
//   points; foot and direction for next queries; status, index, point and normal for results).
//   Decoding fills that array and never allocates; a count above `capacity` or FF_MAX_BATCH
//   fails before any item is read. XDR_FREE does nothing.
//
// Every filter fails (returns FALSE) on a short stream or an oversize count, never reads or
// writes past the stream or the array.
#pragma once

#include <endian.h>
#include <rpc/rpc.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "footfall.h"

namespace footfall {

// Drop-in, wire- and memory-identical replacements for the rpcgen routines (see above).
bool_t FastXdrPointBatchArgs(XDR* xdrs, ff_point_batch_args* args);
bool_t FastXdrNextBatchArgs(XDR* xdrs, ff_next_batch_args* args);
bool_t FastXdrBatchReply(XDR* xdrs, ff_batch_reply* reply);

// ff_point_batch_args with its points in a caller-owned array of `capacity` items.
template <typename Vec>
struct PointBatchView {
  u_int terrain = 0;
  u_int count = 0;  // items in use
  Vec* points = nullptr;
  u_int capacity = 0;  // items `points` holds; decoding refuses more
};

// ff_next_batch_args with its queries (fields foot, direction) in a caller-owned array.
template <typename Step>
struct NextBatchView {
  u_int terrain = 0;
  double tolerance = 0;  // [Units: wu]
  u_int count = 0;
  Step* queries = nullptr;
  u_int capacity = 0;
};

// ff_batch_reply with its results (fields status, index, point, normal) in a caller-owned array.
// `status` comes first, as in every reply type of footfall.x.
template <typename Result>
struct BatchReplyView {
  ff_status status = FF_OK;
  u_int count = 0;
  Result* results = nullptr;
  u_int capacity = 0;
};

template <typename Vec>
bool_t XdrPointBatchView(XDR* xdrs, PointBatchView<Vec>* view);
template <typename Step>
bool_t XdrNextBatchView(XDR* xdrs, NextBatchView<Step>* view);
template <typename Result>
bool_t XdrBatchReplyView(XDR* xdrs, BatchReplyView<Result>* view);

// A filter as the xdrproc_t that clnt_call, svc_getargs and svc_sendreply take.
template <typename T>
xdrproc_t AsXdrProc(bool_t (*filter)(XDR*, T*)) {
  return reinterpret_cast<xdrproc_t>(filter);
}

// --- implementation --------------------------------------------------------------------------

namespace xdr_detail {

// Items per XDR_INLINE request: large enough to amortise the call, small enough to fit in
// what a record stream has already read.
constexpr u_int kInlineItems = 64;

inline void PutU32(char* p, uint32_t v) {
  v = htobe32(v);
  std::memcpy(p, &v, 4);
}
inline uint32_t GetU32(const char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return be32toh(v);
}
inline void PutDouble(char* p, double d) {
  uint64_t v;
  std::memcpy(&v, &d, 8);
  v = htobe64(v);
  std::memcpy(p, &v, 8);
}
inline double GetDouble(const char* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  v = be64toh(v);
  double d;
  std::memcpy(&d, &v, 8);
  return d;
}

// An enum field (ff_status or footfall::Status) as its 4-byte XDR int, whatever its C++ type.
template <typename E>
int32_t EnumBits(const E& e) {
  static_assert(sizeof(E) == 4, "enums travel as 4-byte XDR ints");
  int32_t v;
  std::memcpy(&v, &e, 4);
  return v;
}
template <typename E>
void SetEnumBits(E* e, int32_t v) {
  static_assert(sizeof(E) == 4, "enums travel as 4-byte XDR ints");
  std::memcpy(e, &v, 4);
}

template <typename Vec>
void PutVec(char* p, const Vec& v) {
  PutDouble(p, v.x), PutDouble(p + 8, v.y), PutDouble(p + 16, v.z);
}
template <typename Vec>
void GetVec(const char* p, Vec* v) {
  v->x = GetDouble(p), v->y = GetDouble(p + 8), v->z = GetDouble(p + 16);
}
template <typename Vec>
bool_t SlowVec(XDR* xdrs, Vec* v) {
  return xdr_double(xdrs, &v->x) && xdr_double(xdrs, &v->y) && xdr_double(xdrs, &v->z);
}

// ff_vec3: three doubles.
struct VecCodec {
  static constexpr u_int kBytes = 24;
  template <typename Vec>
  static void Put(char* p, const Vec& v) {
    PutVec(p, v);
  }
  template <typename Vec>
  static void Get(const char* p, Vec* v) {
    GetVec(p, v);
  }
  template <typename Vec>
  static bool_t Slow(XDR* xdrs, Vec* v) {
    return SlowVec(xdrs, v);
  }
};

// ff_next_query: foot, direction.
struct StepCodec {
  static constexpr u_int kBytes = 48;
  template <typename Step>
  static void Put(char* p, const Step& s) {
    PutVec(p, s.foot), PutVec(p + 24, s.direction);
  }
  template <typename Step>
  static void Get(const char* p, Step* s) {
    GetVec(p, &s->foot), GetVec(p + 24, &s->direction);
  }
  template <typename Step>
  static bool_t Slow(XDR* xdrs, Step* s) {
    return SlowVec(xdrs, &s->foot) && SlowVec(xdrs, &s->direction);
  }
};

// ff_result: status (enum), index (u_int), point, normal.
struct ResultCodec {
  static constexpr u_int kBytes = 56;
  template <typename Result>
  static void Put(char* p, const Result& r) {
    PutU32(p, static_cast<uint32_t>(EnumBits(r.status)));
    PutU32(p + 4, r.index);
    PutVec(p + 8, r.point), PutVec(p + 32, r.normal);
  }
  template <typename Result>
  static void Get(const char* p, Result* r) {
    SetEnumBits(&r->status, static_cast<int32_t>(GetU32(p)));
    r->index = GetU32(p + 4);
    GetVec(p + 8, &r->point), GetVec(p + 32, &r->normal);
  }
  template <typename Result>
  static bool_t Slow(XDR* xdrs, Result* r) {
    int32_t status = EnumBits(r->status);
    u_int index = r->index;
    if (!xdr_int32_t(xdrs, &status) || !xdr_u_int(xdrs, &index)) return FALSE;
    SetEnumBits(&r->status, status);
    r->index = index;
    return SlowVec(xdrs, &r->point) && SlowVec(xdrs, &r->normal);
  }
};

// Puts or gets `count` items (not their count): inline chunks where the stream allows,
// element-wise otherwise. XDR_FREE touches nothing.
template <typename Codec, typename T>
bool_t Items(XDR* xdrs, T* items, u_int count) {
  if (xdrs->x_op == XDR_FREE) return TRUE;
  u_int i = 0;
  while (i < count) {
    const u_int k = std::min(count - i, kInlineItems);
    char* buf = reinterpret_cast<char*>(XDR_INLINE(xdrs, k * Codec::kBytes));
    if (buf) {
      if (xdrs->x_op == XDR_ENCODE) {
        for (u_int j = 0; j < k; ++j) Codec::Put(buf + j * Codec::kBytes, items[i + j]);
      } else {
        for (u_int j = 0; j < k; ++j) Codec::Get(buf + j * Codec::kBytes, &items[i + j]);
      }
      i += k;
    } else {
      if (!Codec::Slow(xdrs, &items[i])) return FALSE;
      ++i;
    }
  }
  return TRUE;
}

// A variable-length array into caller-owned storage: the count, then the items.
template <typename Codec, typename T>
bool_t ViewArray(XDR* xdrs, T* items, u_int* count, u_int capacity) {
  if (xdrs->x_op == XDR_FREE) return TRUE;
  if (!xdr_u_int(xdrs, count)) return FALSE;
  if (*count > capacity || *count > FF_MAX_BATCH || (*count > 0 && !items)) {
    if (xdrs->x_op == XDR_DECODE) *count = 0;
    return FALSE;
  }
  return Items<Codec>(xdrs, items, *count);
}

}  // namespace xdr_detail

template <typename Vec>
bool_t XdrPointBatchView(XDR* xdrs, PointBatchView<Vec>* view) {
  if (xdrs->x_op == XDR_FREE) return TRUE;
  return xdr_u_int(xdrs, &view->terrain) && xdr_detail::ViewArray<xdr_detail::VecCodec>(
                                                xdrs, view->points, &view->count, view->capacity);
}

template <typename Step>
bool_t XdrNextBatchView(XDR* xdrs, NextBatchView<Step>* view) {
  if (xdrs->x_op == XDR_FREE) return TRUE;
  return xdr_u_int(xdrs, &view->terrain) && xdr_double(xdrs, &view->tolerance) &&
         xdr_detail::ViewArray<xdr_detail::StepCodec>(xdrs, view->queries, &view->count,
                                                      view->capacity);
}

template <typename Result>
bool_t XdrBatchReplyView(XDR* xdrs, BatchReplyView<Result>* view) {
  if (xdrs->x_op == XDR_FREE) return TRUE;
  int32_t status = xdr_detail::EnumBits(view->status);
  if (!xdr_int32_t(xdrs, &status)) return FALSE;
  xdr_detail::SetEnumBits(&view->status, status);
  return xdr_detail::ViewArray<xdr_detail::ResultCodec>(xdrs, view->results, &view->count,
                                                        view->capacity);
}

}  // namespace footfall
