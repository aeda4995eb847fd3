#include "footfall/terrain/status.h"

namespace footfall {

const char* StatusName(Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kNoFoothold:
      return "no_foothold";
    case Status::kInvalidArgument:
      return "invalid_argument";
    case Status::kUnknownTerrain:
      return "unknown_terrain";
    case Status::kLimitExceeded:
      return "limit_exceeded";
    case Status::kIoError:
      return "io_error";
    case Status::kParseError:
      return "parse_error";
    case Status::kAccessDenied:
      return "access_denied";
    case Status::kUnavailable:
      return "unavailable";
    case Status::kInternalError:
      return "internal_error";
  }
  return "unknown_status";
}

}  // namespace footfall
