// Opens an ONC RPC client to footfalld: our own socket with a bounded non-blocking connect,
// wrapped by clnt_vc_create with a send size that keeps every request in one record fragment
// (footfalld's non-blocking transport drops multi-fragment requests). Internal to client/lib.
#pragma once

#include <rpc/rpc.h>

#include <string>

#include "footfall/client/terrain_session.h"

namespace footfall {

// Connects to options.host:options.port within options.connect_timeout_s per address and sets
// the per-call timeout to options.call_timeout_s. Returns nullptr and the reason (one line,
// without the address) in *reason when no address could be reached. The client owns its socket
// (CLSET_FD_CLOSE): clnt_destroy closes it.
CLIENT* ConnectFootfalld(const RpcOptions& options, std::string* reason);

// Sets how long the client's calls wait for their answer. [Units: s]
void SetCallTimeout(CLIENT* client, double seconds);

}  // namespace footfall
