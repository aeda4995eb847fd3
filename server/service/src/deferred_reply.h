// Replies sent after the dispatcher has returned (internal to footfall::service).
//
// libtirpc replies from inside the dispatch function, on the RPC thread. A request whose answer
// takes seconds (a server-side load) is instead held: its connection is read no further (the
// client waits for this reply anyway), the work goes to another thread, and the reply is sent
// from the RPC thread when the work is done. libtirpc may close a held connection meanwhile
// (the client went away, or at the descriptor limit); a held transport's destroy is watched, so
// a reply for a closed connection is dropped rather than written to freed memory.
#pragma once

#include <rpc/rpc.h>

#include <cstdint>
#include <set>

namespace footfall {

// Holds the request just dispatched on `transport` for a later SendHeldReply. Returns its
// ticket (never 0). Throws std::bad_alloc, holding nothing, when memory runs out.
uint64_t HoldReply(SVCXPRT* transport);

// Releases ticket `ticket` without a reply: its connection is read again as any other.
void ReleaseHeldReply(uint64_t ticket) noexcept;

// Sends the reply of ticket `ticket`, encoded with `encode`, if its connection is still open, and
// releases the ticket. False when the connection had closed (nothing is sent) or the send failed.
bool SendHeldReply(uint64_t ticket, xdrproc_t encode, void* reply);

// Whether the connection of ticket `ticket` is still open.
bool HeldReplyOpen(uint64_t ticket);

// Whether a reply is held on `transport`.
bool ReplyHeld(const SVCXPRT* transport);

// The sockets of the connections with a held reply: not to be read from until it is sent.
const std::set<int>& HeldSockets();

}  // namespace footfall
