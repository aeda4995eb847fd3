#include "file_output.h"

#include "footfall/terrain/output_file.h"
#include "walk_prep.h"

namespace footfall {
namespace walk_export {

Status WriteFileBytes(const std::string& path, const std::string& bytes, std::string* error) {
  std::string message;
  const Status status = ReplaceFile(path, bytes, &message);
  if (status != Status::kOk) SetError(error, message);
  return status;
}

}  // namespace walk_export
}  // namespace footfall
