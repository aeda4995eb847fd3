#include "file_output.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "walk_prep.h"

namespace footfall {
namespace walk_export {

Status WriteFileBytes(const std::string& path, const std::string& bytes, std::string* error) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    SetError(error, "cannot open '" + path + "' for writing: " + std::strerror(errno));
    return Status::kIoError;
  }
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), file);
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (written != bytes.size()) {
    SetError(error, "cannot write '" + path + "': " + std::strerror(write_errno));
    return Status::kIoError;
  }
  if (!closed) {
    SetError(error, "cannot write '" + path + "' (close failed): " + std::strerror(errno));
    return Status::kIoError;
  }
  return Status::kOk;
}

}  // namespace walk_export
}  // namespace footfall
