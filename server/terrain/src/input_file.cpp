#include "footfall/terrain/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <string>

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

bool LineReader::Next(std::string* line) {
  line->clear();
  if (too_long_ || !in_.good()) return false;
  // istream::getline stores at most size - 1 bytes: stopping there (failbit, not at the end of
  // the file) tells a long line apart. It counts a '\n' it took, which it does not store.
  if (buffer_.size() < kMaxLineBytes + 1) buffer_.resize(kMaxLineBytes + 1);
  in_.getline(&buffer_[0], static_cast<std::streamsize>(buffer_.size()));
  const size_t taken = static_cast<size_t>(in_.gcount());
  if (in_.fail()) {
    if (!in_.eof() && taken == kMaxLineBytes) too_long_ = true, ++number_;
    return false;  // a long line, the end of the stream (nothing taken) or a read error
  }
  const bool took_newline = !in_.eof();
  line->assign(buffer_.data(), took_newline ? taken - 1 : taken);
  ++number_;
  return true;
}

std::string LineReader::TooLongMessage(const char* expected) {
  return std::string("line longer than 1 MiB (expected ") + expected + ")";
}

}  // namespace footfall
