// The check every reader of a named input file makes before opening it.
#pragma once

#include <string>

#include "footfall/terrain/status.h"

namespace footfall {

// kOk when `path` is a regular file (links followed). Otherwise the status and
// "PATH: cannot open WHAT: REASON" in *error: kIoError when it does not exist or cannot be
// examined, kInvalidArgument for directories, FIFOs, devices and sockets (opening a FIFO would
// wait for a writer; a device may never end).
Status CheckInputFile(const std::string& path, const char* what, std::string* error);

}  // namespace footfall
