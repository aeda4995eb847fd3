#include "footfall/terrain/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace footfall {

Status CheckInputFile(const std::string& path, const char* what, std::string* error) {
  struct stat st;
  std::string why;
  Status status = Status::kOk;
  if (::stat(path.c_str(), &st) != 0) {
    why = std::strerror(errno), status = Status::kIoError;
  } else if (S_ISDIR(st.st_mode)) {
    why = "a directory", status = Status::kInvalidArgument;
  } else if (!S_ISREG(st.st_mode)) {
    why = S_ISFIFO(st.st_mode)   ? "a FIFO, not a regular file"
          : S_ISSOCK(st.st_mode) ? "a socket, not a regular file"
                                 : "a device, not a regular file";
    status = Status::kInvalidArgument;
  }
  if (status != Status::kOk && error) *error = path + ": cannot open " + what + ": " + why;
  return status;
}

}  // namespace footfall
