// Status codes shared by the terrain engine, the RPC protocol (rpc/footfall.x, enum ff_status)
// and the client library, so a result means the same on both sides of the wire.
#pragma once

#include <cstdint>

namespace footfall {

enum class Status : int32_t {
  kOk = 0,
  kNoFoothold = 1,       // a valid next query found no candidate sample
  kInvalidArgument = 2,  // NaN/Inf input, zero direction, bad handle value ...
  kUnknownTerrain = 3,   // no terrain has this handle
  kLimitExceeded = 4,    // a size limit of the engine or the server
  kIoError = 5,          // a file could not be read or written
  kParseError = 6,       // a file's content is malformed
  kAccessDenied = 7,     // a path outside the server's data root
  kUnavailable = 8,      // the server cannot be reached or stopped answering
  kInternalError = 9,
};

// A short stable name for a status, e.g. "no_foothold".
const char* StatusName(Status status);

}  // namespace footfall
