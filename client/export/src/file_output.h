// Writing an exporter's bytes to a file, with I/O errors reported as values.
#pragma once

#include <string>

#include "footfall/terrain/status.h"

namespace footfall {
namespace walk_export {

// Replaces the file at `path` with `bytes` (ReplaceFile: a failed write leaves the old file
// whole). kIoError with a message naming the path and the system's reason.
Status WriteFileBytes(const std::string& path, const std::string& bytes, std::string* error);

}  // namespace walk_export
}  // namespace footfall
