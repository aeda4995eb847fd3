// The drop-in fast filters: rpcgen's memory contract (xdr_array's) with inline item coding.
#include "footfall/rpc/batch_xdr.h"

#include <climits>
#include <cstdlib>

namespace footfall {
namespace {

// As libtirpc's xdr_array: the count (bounded by `max`), allocation on decode when *items is
// NULL (calloc, as mem_alloc), the items, and free on XDR_FREE (free, as mem_free). A failed
// decode leaves the allocated array for XDR_FREE to release.
template <typename Codec, typename T>
bool_t Array(XDR* xdrs, T** items, u_int* count, u_int max) {
  if (!xdr_u_int(xdrs, count)) return FALSE;
  const u_int c = *count;
  if ((c > max || UINT_MAX / sizeof(T) < c) && xdrs->x_op != XDR_FREE) return FALSE;
  switch (xdrs->x_op) {
    case XDR_FREE:
      std::free(*items);
      *items = nullptr;
      return TRUE;
    case XDR_DECODE:
      if (!*items) {
        if (c == 0) return TRUE;
        *items = static_cast<T*>(std::calloc(c, sizeof(T)));
        if (!*items) return FALSE;
      }
      break;
    case XDR_ENCODE:
      break;
  }
  return xdr_detail::Items<Codec>(xdrs, *items, c);
}

}  // namespace

bool_t FastXdrPointBatchArgs(XDR* xdrs, ff_point_batch_args* args) {
  return xdr_u_int(xdrs, &args->terrain) &&
         Array<xdr_detail::VecCodec>(xdrs, &args->points.points_val, &args->points.points_len,
                                     FF_MAX_BATCH);
}

bool_t FastXdrNextBatchArgs(XDR* xdrs, ff_next_batch_args* args) {
  return xdr_u_int(xdrs, &args->terrain) && xdr_double(xdrs, &args->tolerance) &&
         Array<xdr_detail::StepCodec>(xdrs, &args->queries.queries_val, &args->queries.queries_len,
                                      FF_MAX_BATCH);
}

bool_t FastXdrBatchReply(XDR* xdrs, ff_batch_reply* reply) {
  int32_t status = xdr_detail::EnumBits(reply->status);
  if (!xdr_int32_t(xdrs, &status)) return FALSE;
  xdr_detail::SetEnumBits(&reply->status, status);
  return Array<xdr_detail::ResultCodec>(xdrs, &reply->results.results_val,
                                        &reply->results.results_len, FF_MAX_BATCH);
}

}  // namespace footfall
