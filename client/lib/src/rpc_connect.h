// Opens an ONC RPC client to footfalld: our own socket with a bounded non-blocking connect,
// wrapped by clnt_vc_create with a send size that keeps every request in one record fragment
// (footfalld's non-blocking transport drops multi-fragment requests). Internal to client/lib.
#pragma once

#include <netdb.h>
#include <rpc/rpc.h>

#include <string>

#include "footfall/client/terrain_session.h"

namespace footfall {

// Connects to options.host:options.port within options.connect_timeout_s per address and sets
// the per-call timeout to options.call_timeout_s. A host name is looked up within
// options.call_timeout_s (ResolveBounded); a literal address needs no lookup. Returns nullptr and
// the reason (one line, without the address) in *reason when no address could be reached. The
// client owns its socket (CLSET_FD_CLOSE): clnt_destroy closes it.
CLIENT* ConnectFootfalld(const RpcOptions& options, std::string* reason);

// A host name lookup, with getaddrinfo's signature and results (freed with freeaddrinfo).
using ResolveFunction = int (*)(const char* host, const char* service, const addrinfo* hints,
                                addrinfo** out);

// Resolves host:service into *out (freed with freeaddrinfo by the caller). A numeric address
// (IPv4, IPv6) is converted at once, without `resolve`. A name is looked up by `resolve` on a
// helper thread, waited for at most timeout_s [Units: s]: a lookup still running then is
// abandoned (its thread frees its result when it ends), and at most kMaxPendingLookups such
// lookups run at once in the process (beyond: refused at once). False with the reason (one line,
// without the address) in *reason.
constexpr int kMaxPendingLookups = 8;
bool ResolveBounded(const std::string& host, const std::string& service, const addrinfo& hints,
                    double timeout_s, ResolveFunction resolve, addrinfo** out, std::string* reason);

// The lookup ConnectFootfalld uses for host names (getaddrinfo unless a test replaced it; null
// restores getaddrinfo).
void SetHostResolver(ResolveFunction resolve);

// Why a call failed, one line: libtirpc's text ("RPC: Unable to receive"), and for a
// connection that failed under the call, what that most likely means (footfalld stopped, was
// killed or closed the connection).
std::string CallFailureText(clnt_stat status);

// Sets how long the client's calls wait for their answer. [Units: s]
void SetCallTimeout(CLIENT* client, double seconds);

// A timeout as the session uses it: NaN and negative values are 0, values above
// kMaxTimeoutSeconds (infinity too) are kMaxTimeoutSeconds, so that no wait overflows a clock.
// [Units: s]
constexpr double kMaxTimeoutSeconds = 1e6;  // about 11.6 days: "for ever", for a call
double BoundedSeconds(double seconds);

// `options` with every timeout bounded by BoundedSeconds.
RpcOptions BoundedTimeouts(RpcOptions options);

}  // namespace footfall
