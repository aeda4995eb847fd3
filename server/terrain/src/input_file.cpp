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
  if (path.empty()) {
    // (stat's "No such file or directory" after a name of nothing: ": cannot open ...".)
    if (error) *error = std::string("cannot open ") + what + ": expected a path, got an empty one";
    return Status::kInvalidArgument;
  }
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

std::string WideTextProblem(std::string_view start) {
  auto byte = [&](size_t i) {
    return i < start.size() ? static_cast<unsigned char>(start[i]) : -1;
  };
  // A character of a text file: printable ASCII or a tab, line end or space.
  auto text = [&](size_t i) {
    const int c = byte(i);
    return (c >= 0x20 && c < 0x7f) || c == '\t' || c == '\n' || c == '\r';
  };
  const char* kind = nullptr;
  if (start.substr(0, 4) == std::string_view("\xFF\xFE\0\0", 4) ||
      start.substr(0, 4) == std::string_view("\0\0\xFE\xFF", 4)) {
    kind = "UTF-32";
  } else if (start.substr(0, 2) == "\xFF\xFE" || start.substr(0, 2) == "\xFE\xFF") {
    kind = "UTF-16";
  } else if (start.size() >= 8 && text(0) && byte(1) == 0 && byte(2) == 0 && byte(3) == 0 &&
             text(4)) {
    kind = "UTF-32";  // little-endian, no byte order mark
  } else if (start.size() >= 8 && byte(0) == 0 && byte(1) == 0 && byte(2) == 0 && text(3) &&
             byte(4) == 0) {
    kind = "UTF-32";  // big-endian
  } else if (start.size() >= 4 && text(0) && byte(1) == 0 && text(2) && byte(3) == 0) {
    kind = "UTF-16";  // little-endian
  } else if (start.size() >= 4 && byte(0) == 0 && text(1) && byte(2) == 0 && text(3)) {
    kind = "UTF-16";  // big-endian
  }
  if (!kind) return "";
  return std::string(kind) + " text (expected ASCII or UTF-8: save the file as UTF-8)";
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
