// The check every reader of a named input file makes before opening it.
#pragma once

#include <istream>
#include <string>
#include <string_view>

#include "footfall/terrain/status.h"

namespace footfall {

// kOk when `path` is a regular file (links followed). Otherwise the status and
// "PATH: cannot open WHAT: REASON" in *error: kIoError when it does not exist or cannot be
// examined, kInvalidArgument for directories, FIFOs, devices and sockets (opening a FIFO would
// wait for a writer; a device may never end).
Status CheckInputFile(const std::string& path, const char* what, std::string* error);

// When `start`, the first bytes of a file (4 or more when it has them), is UTF-16 or UTF-32
// text, with a byte order mark or without one (ASCII characters each followed or preceded by
// NUL bytes): "UTF-16 text (expected ASCII or UTF-8: save the file as UTF-8)", or UTF-32. ""
// otherwise (ASCII, UTF-8, binary).
std::string WideTextProblem(std::string_view start);

// The longest line a text terrain file may have. [Units: bytes] A file of NUL bytes or one
// without line breaks is refused at its first line instead of being read whole.
constexpr size_t kMaxLineBytes = size_t{1} << 20;

// Reads a text file line by line as std::getline does (the '\n' dropped, a last line without
// one included), but no line longer than kMaxLineBytes.
class LineReader {
 public:
  explicit LineReader(std::istream& in) : in_(in) {}
  // The next line into *line; false at the end of the stream, on a read error, and on a line
  // longer than kMaxLineBytes (too_long() then true; the stream is left there).
  bool Next(std::string* line);
  bool too_long() const { return too_long_; }
  // The first kMaxLineBytes bytes of the line too long (empty unless too_long()): what it holds
  // (a file of CR-only line ends read as one line) can say more than its length.
  std::string_view too_long_start() const {
    return too_long_ ? std::string_view(buffer_.data(), kMaxLineBytes) : std::string_view();
  }
  // The 1-based number of the line last returned, or of the line too long.
  size_t line_number() const { return number_; }
  // "line longer than 1 MiB (expected text lines ...)": for a message at the line's number.
  static std::string TooLongMessage(const char* expected);

 private:
  std::istream& in_;
  std::string buffer_;
  bool too_long_ = false;
  size_t number_ = 0;
};

}  // namespace footfall
