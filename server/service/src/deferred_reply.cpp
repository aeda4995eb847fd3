#include "deferred_reply.h"

#include <map>
#include <memory>
#include <type_traits>

namespace footfall {
namespace {

using TransportOps = std::remove_const_t<std::remove_pointer_t<decltype(SVCXPRT::xp_ops)>>;

struct Held {
  SVCXPRT* transport = nullptr;  // nullptr once libtirpc has destroyed it
  int socket = -1;
  const TransportOps* original = nullptr;
  // The original's, with xp_destroy replaced by Destroyed and xp_recv by Received: libtirpc's
  // idle sweep at the descriptor limit destroys only transports whose xp_recv is its own
  // (bypassing xp_destroy), so it leaves a held connection alone.
  TransportOps watched{};
};

std::map<uint64_t, std::unique_ptr<Held>> g_held;  // by ticket
std::map<const SVCXPRT*, uint64_t> g_tickets;      // by transport, while it lives
std::set<int> g_sockets;
uint64_t g_next_ticket = 1;

// The watched transport's destroy: forgets it, then destroys it as libtirpc meant to.
void Destroyed(SVCXPRT* transport) {
  const auto it = g_tickets.find(transport);
  if (it != g_tickets.end()) {
    Held& h = *g_held.at(it->second);
    transport->xp_ops = h.original;
    h.transport = nullptr;
    g_sockets.erase(h.socket);
    g_tickets.erase(it);
  }
  transport->xp_ops->xp_destroy(transport);
}

// The watched transport's receive: as libtirpc's (a held connection is read only once it is in
// error, to close it).
bool_t Received(SVCXPRT* transport, rpc_msg* message) {
  return g_held.at(g_tickets.at(transport))->original->xp_recv(transport, message);
}

}  // namespace

uint64_t HoldReply(SVCXPRT* transport) {
  const uint64_t ticket = g_next_ticket++;
  auto h = std::make_unique<Held>();
  h->transport = transport;
  h->socket = transport->xp_fd;
  h->original = transport->xp_ops;
  h->watched = *transport->xp_ops;
  h->watched.xp_destroy = Destroyed;
  h->watched.xp_recv = Received;
  // Every entry made before the transport is watched, and all undone if memory runs out, so
  // that the three never disagree (a transport watched without its entry was read through a
  // missing one, and ended the server).
  const auto held = g_held.emplace(ticket, nullptr).first;
  try {
    g_tickets[transport] = ticket;
    g_sockets.insert(h->socket);
  } catch (...) {
    g_tickets.erase(transport);
    g_held.erase(held);
    throw;
  }
  held->second = std::move(h);
  transport->xp_ops = &held->second->watched;
  return ticket;
}

void ReleaseHeldReply(uint64_t ticket) noexcept {
  const auto it = g_held.find(ticket);
  if (it == g_held.end()) return;
  Held& h = *it->second;
  if (h.transport) {
    h.transport->xp_ops = h.original;
    g_tickets.erase(h.transport);
    g_sockets.erase(h.socket);
  }
  g_held.erase(it);
}

bool SendHeldReply(uint64_t ticket, xdrproc_t encode, void* reply) {
  const auto it = g_held.find(ticket);
  if (it == g_held.end()) return false;
  const std::unique_ptr<Held> h = std::move(it->second);
  g_held.erase(it);
  if (!h->transport) return false;  // closed meanwhile
  h->transport->xp_ops = h->original;
  g_tickets.erase(h->transport);
  g_sockets.erase(h->socket);
  return svc_sendreply(h->transport, encode, static_cast<char*>(reply));
}

bool HeldReplyOpen(uint64_t ticket) {
  const auto it = g_held.find(ticket);
  return it != g_held.end() && it->second->transport != nullptr;
}

bool ReplyHeld(const SVCXPRT* transport) { return g_tickets.count(transport) != 0; }

const std::set<int>& HeldSockets() { return g_sockets; }

}  // namespace footfall
