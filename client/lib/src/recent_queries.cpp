// The FF_RECENT client: one connection, kept between polls.
#include "footfall/client/recent_queries.h"

#include <rpc/rpc.h>

#include <csignal>
#include <cstring>

#include "footfall.h"
#include "rpc_connect.h"

namespace footfall {
namespace {

Vec3 FromWire(const ff_vec3& v) { return {v.x, v.y, v.z}; }

Status FromWire(ff_status s) {
  const int v = static_cast<int>(s);
  return v >= FF_OK && v <= FF_INTERNAL_ERROR ? static_cast<Status>(v) : Status::kInternalError;
}

}  // namespace

struct RecentQueryFeed::Connection {
  CLIENT* client = nullptr;
};

RecentQueryFeed::RecentQueryFeed(const RpcOptions& options)
    : options_(BoundedTimeouts(options)), connection_(std::make_unique<Connection>()) {
  std::signal(SIGPIPE, SIG_IGN);
}

RecentQueryFeed::~RecentQueryFeed() { Disconnect(); }

std::string RecentQueryFeed::Address() const {
  return FormatHostPort(options_.host, options_.port);
}

Status RecentQueryFeed::Fail(Status status, std::string message) {
  last_error_ = std::move(message);
  return status;
}

void RecentQueryFeed::Disconnect() {
  if (connection_ && connection_->client) {
    clnt_destroy(connection_->client);
    connection_->client = nullptr;
  }
}

Status RecentQueryFeed::EnsureConnected() {
  if (connection_->client) return Status::kOk;
  std::string reason;
  connection_->client = ConnectFootfalld(options_, &reason);
  if (!connection_->client)
    return Fail(Status::kUnavailable, "footfalld at " + Address() + ": " + reason);
  return Status::kOk;
}

Status RecentQueryFeed::Fetch(std::vector<RecentQuery>* out, uint64_t* latest) {
  Status s = EnsureConnected();
  if (s != Status::kOk) return s;
  ff_recent_args args{after_};
  ff_recent_reply reply;
  std::memset(&reply, 0, sizeof reply);
  const clnt_stat cs = ff_recent_1(&args, &reply, connection_->client);
  if (cs != RPC_SUCCESS) {
    const std::string reason = CallFailureText(cs);
    Disconnect();
    return Fail(Status::kUnavailable, "recent: footfalld at " + Address() + ": " + reason);
  }
  s = FromWire(reply.status);
  if (s == Status::kOk) {
    *latest = reply.latest;
    for (u_int i = 0; out && i < reply.queries.queries_len; ++i) {
      const ff_recent_query& w = reply.queries.queries_val[i];
      RecentQuery q;
      q.sequence = w.sequence;
      q.terrain = w.terrain;
      q.op = w.op == FF_OP_NEXT     ? QueryOp::kNext
             : w.op == FF_OP_NORMAL ? QueryOp::kNormal
                                    : QueryOp::kSnap;
      q.point = FromWire(w.point);
      q.direction = FromWire(w.direction);
      q.tolerance = w.tolerance;
      q.result.status = FromWire(w.result.status);
      if (q.result.status == Status::kOk) {
        q.result.index = w.result.index;
        q.result.point = FromWire(w.result.point);
        q.result.normal = FromWire(w.result.normal);
      }
      if (q.sequence <= after_) continue;  // never report a query twice
      if (q.sequence > after_ + 1) missed_ += q.sequence - after_ - 1;
      after_ = q.sequence;
      out->push_back(q);
    }
  }
  xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_recent_reply), reinterpret_cast<char*>(&reply));
  if (s != Status::kOk)
    return Fail(s, "recent: footfalld at " + Address() + " answered " + StatusName(s));
  return Status::kOk;
}

Status RecentQueryFeed::Start() {
  uint64_t latest = 0;
  after_ = UINT64_MAX;  // ask for nothing: only the server's latest sequence
  const Status s = Fetch(nullptr, &latest);
  after_ = s == Status::kOk ? latest : 0;
  return s;
}

Status RecentQueryFeed::Poll(std::vector<RecentQuery>* out) {
  uint64_t latest = 0;
  const Status s = Fetch(out, &latest);
  // A restarted server counts from 1 again: follow it from its beginning.
  if (s == Status::kOk && latest < after_) after_ = 0;
  return s;
}

}  // namespace footfall
