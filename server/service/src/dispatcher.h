// The RPC dispatcher of footfalld (internal to footfall::service).
#pragma once

#include <rpc/rpc.h>

#include "footfall/service/terrain_registry.h"

namespace footfall {

struct ServiceState {
  TerrainRegistry registry;
  int batch_threads = 1;
};

using DispatchFn = void (*)(svc_req*, SVCXPRT*);

// Makes `state` the one the dispatcher serves, and returns the function to register with
// svc_register. One state per process (libtirpc's svc layer is process-global).
DispatchFn InstallDispatcher(ServiceState* state);

}  // namespace footfall
