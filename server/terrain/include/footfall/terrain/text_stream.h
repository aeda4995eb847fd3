// The string stream messages, notes and overlays are written with: the "C" locale whatever the
// host set, and its text whole or an exception, never cut short.
#pragma once

#include <locale>
#include <new>
#include <sstream>
#include <string>

namespace footfall {

// An std::ostringstream in the classic "C" locale (numbers read the same whatever global C++
// locale a host process set), with `precision` significant digits. str() is the whole text
// written, or throws std::bad_alloc when memory ran out while it was written: a plain string
// stream swallows the failure, sets its badbit and keeps what it had, so a stop reason or an
// error message would be cut short without a word.
class TextStream : public std::ostringstream {
 public:
  explicit TextStream(int precision = 6) {
    imbue(std::locale::classic());
    this->precision(precision);
  }

  using std::ostringstream::str;  // str(text): starts the stream over with `text`
  std::string str() const {
    if (bad()) throw std::bad_alloc();
    return std::ostringstream::str();
  }
};

}  // namespace footfall
